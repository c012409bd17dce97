"""Embroidery hoops, file-format limits and machine speed, read from `profiles/embroidery.toml`.

Capabilities are data: the stitch planner asks this module for the longest stitch a
format can hold and the hoop's sewing field instead of branching on names. Lengths come
back in millimetres. The sewing field of a hoop is centred on (0, 0), like the designs.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from onestroke.units import parse_positive_length, parse_size_pair

PROFILE_PATH = Path(__file__).with_name("profiles") / "embroidery.toml"
# A machine's sewing speed, stitches per minute (home machines 350-1000, industrial ones
# up to about 1500; 3000 leaves room).
SPM = Range(100.0, 3000.0, name="--spm")
# A sewing field's side: home machines sew up to about 400 mm, commercial single heads up to
# about 500 mm, large-field multi-head frames about 1,200 mm; 1,500 mm leaves room and keeps
# the densest stitching a request can ask for bounded (the studio answers it within 2 s).
HOOP_SIDE = Range(0.0, 1500.0, unit="mm", name="--hoop side", low_open=True)


@dataclass(frozen=True, kw_only=True)
class Hoop:
    """A sewing field `width` x `height` in mm, centred on (0, 0)."""

    name: str
    width: float = ranged(100.0, HOOP_SIDE)
    height: float = ranged(100.0, HOOP_SIDE)
    aliases: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        check_ranges(self)

    def contains(self, bounds: tuple[float, float, float, float], *, slack: float = 1e-9) -> bool:
        """True when the box (xmin, ymin, xmax, ymax) in mm lies inside the field."""
        xmin, ymin, xmax, ymax = bounds
        return (xmin >= -self.width / 2 - slack and xmax <= self.width / 2 + slack
                and ymin >= -self.height / 2 - slack and ymax <= self.height / 2 + slack)

    @property
    def label(self) -> str:
        """Name plus aliases for messages, e.g. '100x100 (4x4)'."""
        return self.name + (f" ({', '.join(self.aliases)})" if self.aliases else "")


@dataclass(frozen=True, kw_only=True)
class EmbroideryFormat:
    """What one file format can hold. Lengths in mm (per axis, per record); full_jump: an
    explicit jump record lands on the first needle point of every run."""

    extension: str
    name: str
    max_stitch: float
    max_jump: float
    trims: str
    max_colors: int
    full_jump: bool = False
    settings: dict = field(default_factory=dict, compare=False)


@dataclass(frozen=True, kw_only=True)
class EmbroideryProfile:
    """Machine speed, the stitch limit, the hoops and the formats of one profile file."""

    stitches_per_minute: float
    trim_seconds: float
    max_stitch: float
    hoops: tuple[Hoop, ...]
    formats: tuple[EmbroideryFormat, ...]

    @property
    def extensions(self) -> tuple[str, ...]:
        """Writable extensions with the dot, e.g. ('.pes', '.dst', ...)."""
        return tuple("." + f.extension for f in self.formats)

    def format_for(self, path: str | os.PathLike) -> EmbroideryFormat:
        """The format chosen by the extension of `path`; `InputError` for any other."""
        suffix = os.path.splitext(str(path))[1].lower().lstrip(".")
        for fmt in self.formats:
            if fmt.extension == suffix:
                return fmt
        shown = f"'.{suffix}'" if suffix else "no extension"
        raise InputError(f"cannot write embroidery as {shown} ({str(path)!r}); use one of "
                         f"{', '.join(self.extensions)}")

    def hoop(self, text: str) -> Hoop:
        """A named hoop ('130x180', '5x7') or a custom field 'WxH' (mm, or with units)."""
        key = str(text).strip().lower().replace(" ", "")
        for hoop in self.hoops:
            if key == hoop.name or key in hoop.aliases:
                return hoop
        if not re.search(r"[xX×]", key):
            names = ", ".join(h.label for h in self.hoops)
            raise InputError(f"unknown hoop {text!r}; use one of {names} or a custom size WxH in mm")
        try:
            width, height = parse_size_pair(text, what="hoop")
        except InputError:
            raise InputError(f"hoop {text!r} is not a sewing field; use WxH with both sides above "
                             "zero (e.g. 120x90 or 4inx4in) or a named hoop") from None
        return Hoop(name=f"{width:g}x{height:g}", width=width, height=height)


def _load(path: Path) -> EmbroideryProfile:
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise InputError(f"cannot read embroidery profile {str(path)!r}: {error}") from None
    machine = data.get("machine", {})
    hoops = tuple(
        Hoop(name=name, width=parse_positive_length(spec["width"], what=f"hoop {name} width"),
             height=parse_positive_length(spec["height"], what=f"hoop {name} height"),
             aliases=tuple(a.lower() for a in spec.get("aliases", ())))
        for name, spec in data.get("hoops", {}).items()
    )
    formats = tuple(
        EmbroideryFormat(extension=ext, name=spec["name"],
                         max_stitch=parse_positive_length(spec["max_stitch"], what=f"{ext} max_stitch"),
                         max_jump=parse_positive_length(spec["max_jump"], what=f"{ext} max_jump"),
                         trims=spec["trims"], max_colors=int(spec["max_colors"]),
                         full_jump=bool(spec.get("full_jump", False)),
                         settings=dict(spec.get("settings", {})))
        for ext, spec in data.get("formats", {}).items()
    )
    return EmbroideryProfile(
        stitches_per_minute=SPM.named("stitches_per_minute").check(float(machine.get("stitches_per_minute", 600))),
        trim_seconds=float(machine.get("trim_seconds", 10)),
        max_stitch=parse_positive_length(machine.get("max_stitch", "12.1mm"), what="max_stitch"),
        hoops=hoops, formats=formats,
    )


@lru_cache(maxsize=8)
def _cached(path: str) -> EmbroideryProfile:
    return _load(Path(path))


def load_embroidery_profile(path: str | os.PathLike | None = None) -> EmbroideryProfile:
    """Read an embroidery profile TOML (default: the bundled `profiles/embroidery.toml`)."""
    return _cached(str(PROFILE_PATH if path is None else path))


def hoop_named(text: str) -> Hoop:
    """Shortcut: a hoop of the bundled profile (see `EmbroideryProfile.hoop`)."""
    return load_embroidery_profile().hoop(text)


def format_for_path(path: str | os.PathLike) -> EmbroideryFormat:
    """Shortcut: the bundled profile's format for the extension of `path`."""
    return load_embroidery_profile().format_for(path)
