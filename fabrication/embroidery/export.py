"""Write a `StitchPlan` as .pes/.dst/.jef/.exp/.vp3 through pyembroidery, atomically.

We hand pyembroidery integer 0.1 mm coordinates (VP3 truncates floats; the other formats
round them) of a plan that already respects the format's stitch limit, so its encoder has
nothing to convert: no stitch becomes a jump, and every format reads back exactly.
Per-format writer settings (PES version, JEF trims) come from the embroidery profile.
"""

from __future__ import annotations

import io
import os

import numpy as np
import pyembroidery

from fabrication.embroidery.plan import JUMP, STITCH, TRIM, StitchPlan
from machines.hoops import EmbroideryFormat, format_for_path
from onestroke.atomic import atomic_write_bytes
from onestroke.errors import FabricationError, InputError

_COMMANDS = np.array([pyembroidery.STITCH, pyembroidery.JUMP, pyembroidery.TRIM])
PES_VERSIONS = (1, 6)


def plan_units(plan: StitchPlan) -> np.ndarray:
    """Plan points as integer 0.1 mm units (N, 2); exact for a plan on the 0.1 mm grid."""
    return np.rint(plan.points * 10.0).astype(np.int64)


def to_pattern(plan: StitchPlan) -> pyembroidery.EmbPattern:
    """A pyembroidery pattern of `plan`: one thread, its rows, then END."""
    pattern = pyembroidery.EmbPattern()
    thread = pyembroidery.EmbThread()
    thread.set_color(*plan.color)
    thread.description = "onestroke #{:02x}{:02x}{:02x}".format(*plan.color)
    pattern.add_thread(thread)
    units = plan_units(plan)
    rows = np.column_stack([units, _COMMANDS[plan.kinds]]).tolist()
    rows.append([rows[-1][0], rows[-1][1], pyembroidery.END])
    pattern.stitches = rows
    return pattern


def check_plan_fits_format(plan: StitchPlan, fmt: EmbroideryFormat) -> None:
    """Raise `FabricationError` if a needle-down stitch exceeds the format's per-axis limit
    (pyembroidery would silently turn it into jumps)."""
    a, b = plan.stitches()
    if len(a):
        longest = float(np.abs(b - a).max()) if len(a) else 0.0
        if longest > fmt.max_stitch + 1e-9:
            raise FabricationError(f"a {longest:.1f} mm stitch exceeds the {fmt.max_stitch:g} mm "
                                   f"limit of {fmt.name}; plan with max_stitch={fmt.max_stitch:g}")


def embroidery_bytes(plan: StitchPlan, fmt: EmbroideryFormat, *, pes_version: int | None = None) -> bytes:
    """The file content of `plan` in format `fmt`."""
    settings = dict(fmt.settings)
    if pes_version is not None:
        if fmt.extension != "pes":
            raise InputError(f"a PES version applies to .pes files only, not .{fmt.extension}")
        if pes_version not in PES_VERSIONS:
            raise InputError(f"PES version {pes_version!r} is not supported; use 1 or 6")
        settings["pes version"] = pes_version
    check_plan_fits_format(plan, fmt)
    writer = getattr(pyembroidery, f"write_{fmt.extension}")
    buffer = io.BytesIO()
    writer(to_pattern(plan), buffer, settings)
    return buffer.getvalue()


def write_embroidery(plan: StitchPlan, path: str | os.PathLike, *, pes_version: int | None = None) -> None:
    """Write `plan` to `path` in the format of its extension, atomically."""
    fmt = format_for_path(path)
    atomic_write_bytes(path, embroidery_bytes(plan, fmt, pes_version=pes_version))


__all__ = ["write_embroidery", "embroidery_bytes", "to_pattern", "plan_units", "STITCH", "JUMP", "TRIM"]
