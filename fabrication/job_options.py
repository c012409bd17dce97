"""Command-line option values (strings such as "2.5mm") to the library's job dataclasses.

Shared by `onestroke embroider`, `onestroke laser`, `onestroke batch` and the studio, so that
one set of option values gives one job and each of them writes the same bytes.
Nothing here prints: warnings come back as one-line messages for the caller to show.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from onestroke.errors import InputError

# A design side this small (mm) given with --width/--height in a zigzag or arrows job is
# worth a hint that --stitch-width is the stitch's width.
SMALL_DESIGN_MM = 15.0

# CLI option -> field name in the style options; which styles use it (for warnings).
_STYLE_FIELDS = {
    "stitch_length": ("stitch_length", "--stitch-length"),
    "tolerance": ("tolerance", "--tolerance"),
    "stitch_width": ("width", "--stitch-width"),
    "spacing": ("spacing", "--spacing"),
    "pull_comp": ("pull_compensation", "--pull-comp"),
    "repeats": ("repeats", "--repeats"),
    "arrow_size": ("size", "--arrow-size"),
    "underlay": ("underlay", "--underlay"),
}


@dataclass(frozen=True, kw_only=True)
class EmbroiderySettings:
    """An embroidery job for one output format: job, PES version, option warnings."""

    job: object  # fabrication.embroidery.pipeline.EmbroideryJob
    extension: str
    pes_version: int | None
    warnings: tuple[str, ...]


@dataclass(frozen=True, kw_only=True)
class LaserSettings:
    """A laser job: profile, toolpath and G-code options, option warnings."""

    profile: object  # machines.laser_profile.LaserProfile
    toolpath: object  # fabrication.laser.toolpath.ToolpathOptions
    gcode: object  # fabrication.laser.gcode_write.GcodeOptions
    warnings: tuple[str, ...]


def _placement(size: str | None, width: str | None, height: str | None, rotate: float):
    from fabrication.placement import PlacementOptions
    from onestroke.units import parse_positive_length

    return PlacementOptions(
        size=parse_positive_length(size, what="--size") if size is not None else None,
        width=parse_positive_length(width, what="--width") if width is not None else None,
        height=parse_positive_length(height, what="--height") if height is not None else None,
        rotate=rotate)


def embroidery_settings(*, output: str, style: str = "running", size: str | None = None,
                        width: str | None = None, height: str | None = None, rotate: float = 0.0,
                        hoop: str = "100x100", fit: bool = False, stitch_length: str | None = None,
                        tolerance: str | None = None, stitch_width: str | None = None,
                        spacing: str | None = None, pull_comp: str | None = None,
                        repeats: int | None = None, arrow_size: str | None = None,
                        underlay: str | None = None, min_stroke: str = "1mm",
                        min_stitch: str = "0.3mm", max_stitch: str = "12.1mm", trim_distance: str = "3mm",
                        lock_form: str = "half", color: str | None = None, thread_chart: str | None = None,
                        start: str | None = None, name: str | None = None, source: str | None = None,
                        date: str | None = None,
                        pes_version: int | None = None, spm: float | None = None) -> EmbroiderySettings:
    """The `EmbroideryJob` of `onestroke embroider`'s option values, for the format of `output`
    (a file name or just ".pes"); `InputError` naming the flag for a bad value. `color`: one
    colour or a comma-separated list (one per stroke); None keeps the drawing's colours.
    `name`: the design name files store (None: the stem of `source`, the input file, else
    'onestroke'). `date`: YYYYMMDDhhmmss for JEF (None: the fixed default)."""
    from fabrication.embroidery.export import PES_VERSIONS
    from fabrication.embroidery.locks import LockOptions
    from fabrication.embroidery.pipeline import EmbroideryJob
    from fabrication.embroidery.plan import PlanOptions, style_options
    from fabrication.embroidery.order import parse_start
    from fabrication.embroidery.plan import FIXED_DATE
    from fabrication.embroidery.thread import check_chart, parse_colors
    from machines.hoops import load_embroidery_profile
    from onestroke.units import parse_length, parse_positive_length

    profile = load_embroidery_profile()
    fmt = profile.format_for(output)
    if pes_version is not None:
        if fmt.extension != "pes":
            raise InputError(f"--pes-version applies to .pes output only, not .{fmt.extension}")
        if pes_version not in PES_VERSIONS:
            raise InputError(f"--pes-version {pes_version} is not supported; use 1 or 6")
    lengths = {name: parse_positive_length(value, what=flag)
               for name, value, flag in (("stitch_length", stitch_length, "--stitch-length"),
                                         ("tolerance", tolerance, "--tolerance"),
                                         ("stitch_width", stitch_width, "--stitch-width"),
                                         ("spacing", spacing, "--spacing"),
                                         ("arrow_size", arrow_size, "--arrow-size")) if value is not None}
    if pull_comp is not None:
        lengths["pull_comp"] = parse_length(pull_comp, what="--pull-comp")
    if repeats is not None:
        lengths["repeats"] = repeats
    if underlay is not None:
        lengths["underlay"] = underlay
    style_values = {_STYLE_FIELDS[k][0]: v for k, v in lengths.items()}
    stitch_options = style_options(style, **style_values)
    warnings = [f"{_STYLE_FIELDS[k][1]} has no effect with --style {style}" for k in lengths
                if _STYLE_FIELDS[k][0] not in type(stitch_options).__dataclass_fields__]
    if not any(v is not None for v in (size, width, height)):
        size = "90mm"
    placement = _placement(size, width, height, rotate)
    limit = min(parse_positive_length(max_stitch, what="--max-stitch"), fmt.max_stitch, profile.max_stitch)
    plan_options = PlanOptions(style=stitch_options, lock=LockOptions(form=lock_form),
                               min_stitch=parse_positive_length(min_stitch, what="--min-stitch"),
                               max_stitch=limit,
                               trim_distance=parse_length(trim_distance, what="--trim-distance"),
                               min_stroke=parse_length(min_stroke, what="--min-stroke"),
                               colors=parse_colors(color) if color is not None else (),
                               thread_chart=check_chart(thread_chart) if thread_chart else None,
                               start=parse_start(start) if start is not None else None)
    if spm is not None and not spm > 0:
        raise InputError(f"--spm {spm:g} must be greater than zero")
    job = EmbroideryJob(placement=placement, hoop=profile.hoop(hoop), fit=fit, plan=plan_options,
                        stitches_per_minute=spm or profile.stitches_per_minute,
                        trim_seconds=profile.trim_seconds, date=date or FIXED_DATE,
                        name=name if name is not None else
                        (os.path.splitext(os.path.basename(source))[0] if source else "onestroke"))
    if style in ("zigzag", "arrows") and stitch_width is None:
        # `--width 3mm` next to --style zigzag most likely meant the zigzag, not the design.
        for flag, side in (("--width", placement.width), ("--height", placement.height)):
            if side is not None and side < SMALL_DESIGN_MM:
                warnings.append(f"{flag} {side:g} mm sizes the whole design; the {style}'s own width is "
                                f"--stitch-width")
    return EmbroiderySettings(job=job, extension=fmt.extension, pes_version=pes_version,
                              warnings=tuple(warnings))


def laser_settings(*, size: str | None = None, width: str | None = None, height: str | None = None,
                   rotate: float = 0.0, origin: str = "lower-left", feed: str = "1500mm/min",
                   power: str = "60%", passes: int = 1, tolerance: str = "0.02mm", arcs: bool = False,
                   keep_order: bool = False, profile_path: str | None = None,
                   air_assist: bool | None = None, return_home: bool = False,
                   profile: object | None = None) -> LaserSettings:
    """The toolpath and G-code options of `onestroke laser`'s option values; `InputError`
    naming the flag for a bad value. `profile`: an already loaded profile, used instead of
    reading `profile_path` (the studio's profiles loaded from the page)."""
    from fabrication.laser.gcode_write import GcodeOptions
    from fabrication.laser.toolpath import ToolpathOptions
    from machines.laser_profile import load_laser_profile
    from onestroke.units import parse_fraction, parse_positive_length, parse_speed

    feed_mm = parse_speed(feed, what="--feed")
    if not feed_mm > 0:
        raise InputError(f"--feed {feed!r} must be greater than 0 mm/min")
    power_fraction = parse_fraction(power, what="--power")
    if power_fraction <= 0:
        raise InputError(f"--power {power!r} must be above 0% (and at most 100%)")
    tol = parse_positive_length(tolerance, what="--tolerance")
    if passes < 1:
        raise InputError(f"--passes {passes} must be at least 1")
    placement = _placement(size, width, height, rotate)
    if profile is None:
        profile = load_laser_profile(profile_path)
    toolpath_options = ToolpathOptions(placement=placement, origin=origin, tolerance=tol, arcs=arcs,
                                       optimize=not keep_order)
    gcode_options = GcodeOptions(feed=feed_mm, power=power_fraction, passes=passes, return_home=return_home,
                                 air_assist=air_assist)
    warnings = []
    if feed_mm > min(profile.max_rate_x, profile.max_rate_y):
        warnings.append(f"--feed {feed_mm:g} mm/min is above the profile's max rate; GRBL will cap it")
    return LaserSettings(profile=profile, toolpath=toolpath_options, gcode=gcode_options,
                         warnings=tuple(warnings))
