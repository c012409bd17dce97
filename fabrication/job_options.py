"""Command-line option values (strings such as "2.5mm") to the library's job dataclasses.

Shared by `onestroke embroider`, `onestroke laser`, `onestroke batch` and the studio, so that
one set of option values gives one job and each of them writes the same bytes. A value is
parsed here and checked against the range its option type declares (`onestroke.ranges`),
with the text as given in the message: the studio's page and the command line get the
same line for the same bad value. Nothing here prints: warnings come back as one-line
messages for the caller to show.
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
    # satin (and the corner controls, zigzag's too)
    "width_scale": ("width_scale", "--width-scale"),
    "min_width": ("min_width", "--min-width"),
    "max_width": ("max_width", "--max-width"),
    "pull_comp_percent": ("pull_compensation_percent", "--pull-comp-percent"),
    "underlay_inset": ("edge_inset", "--underlay-inset"),
    "underlay_spacing": ("underlay_spacing", "--underlay-spacing"),
    "short_stitch_distance": ("short_stitch_distance", "--short-stitch-distance"),
    "short_stitch_inset": ("short_stitch_inset", "--short-stitch-inset"),
    "split_length": ("max_stitch_length", "--split-length"),
    "random_width": ("random_width", "--random-width"),
    "random_phase": ("random_phase", "--random-phase"),
    "seed": ("seed", "--seed"),
    "corner_angle": ("corner_angle", "--corner-angle"),
    "mitre_limit": ("mitre_limit", "--mitre-limit"),
    "corner_overlap": ("overlap", "--corner-overlap"),
}
# How each option's text is read (default: a length).
_PERCENTS = ("pull_comp_percent", "short_stitch_inset", "random_width")
_NUMBERS = ("width_scale", "corner_angle", "mitre_limit")


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


def _checked(value, parse, limits):
    """`value` (text such as "2.5mm", or a number in the library's unit) parsed by `parse`
    and checked against `limits`; None stays None. The message shows text as the CLI's
    types do: quoted where it carries a unit."""
    if value is None:
        return None
    number = parse(value, what=limits.name)
    if not isinstance(value, str):
        return limits.check(number)
    return limits.check(number, shown=value.strip() if parse in (_whole, _number) else repr(value))


def _whole(value, *, what: str):
    """An integer option given as text (the one number grammar: ASCII digits) or a number."""
    from onestroke.units import parse_integer

    if isinstance(value, str):
        return parse_integer(value, what=what)
    if isinstance(value, bool) or (isinstance(value, float) and not value.is_integer()):
        raise InputError(f"{what} {value!r} is not a whole number")
    try:
        return int(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} {value!r} is not a whole number") from None


def _number(value, *, what: str):
    """A plain number option given as text or a number."""
    from onestroke.units import parse_number

    return parse_number(value, what=what)


def _placement(size, width, height, rotate):
    from fabrication.placement import PlacementOptions
    from onestroke.ranges import ranges_of
    from onestroke.units import parse_length

    sides = ranges_of(PlacementOptions)
    return PlacementOptions(size=_checked(size, parse_length, sides["size"]),
                            width=_checked(width, parse_length, sides["width"]),
                            height=_checked(height, parse_length, sides["height"]),
                            rotate=_checked(rotate, _number, sides["rotate"]))


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
                        pes_version: int | None = None, spm: float | None = None,
                        **column: str | float | bool | None) -> EmbroiderySettings:
    """The `EmbroideryJob` of `onestroke embroider`'s option values, for the format of `output`
    (a file name or just ".pes"); `InputError` naming the flag for a bad value. `color`: one
    colour or a comma-separated list (one per stroke); None keeps the drawing's colours.
    `name`: the design name files store (None: the stem of `source`, the input file, else
    'onestroke'). `date`: YYYYMMDDhhmmss for JEF (None: the fixed default). `column`: the
    satin's and the corners' options by their CLI names (width_scale="1.2", min_width="0.8mm",
    short_stitch_inset="15%", random_phase=True, seed=3, ...; see `_STYLE_FIELDS`)."""
    from fabrication.embroidery.export import check_pes_version
    from fabrication.embroidery.locks import LockOptions
    from fabrication.embroidery.order import parse_start
    from fabrication.embroidery.pipeline import EmbroideryJob
    from fabrication.embroidery.plan import FIXED_DATE, PlanOptions, style_class
    from fabrication.embroidery.thread import check_chart, parse_colors
    from machines.hoops import load_embroidery_profile
    from onestroke.ranges import ranges_of
    from onestroke.units import parse_fraction, parse_length

    profile = load_embroidery_profile()
    fmt = profile.format_for(output)
    pes_version = check_pes_version(pes_version, fmt.extension)
    unknown = sorted(set(column) - set(_STYLE_FIELDS))
    if unknown:
        raise InputError(f"unknown embroidery option {unknown[0]!r}")
    given = {"stitch_length": stitch_length, "tolerance": tolerance, "stitch_width": stitch_width,
             "spacing": spacing, "arrow_size": arrow_size, "pull_comp": pull_comp, "repeats": repeats,
             "underlay": underlay, **column}
    cls = style_class(style)
    style_ranges = ranges_of(cls)
    style_values, warnings = {}, []
    for key, value in given.items():
        field, flag = _STYLE_FIELDS[key]
        if value is None or (key == "random_phase" and value is False):
            continue
        if field not in cls.__dataclass_fields__:
            warnings.append(f"{flag} has no effect with --style {style}")
        elif key in ("underlay", "random_phase"):
            style_values[field] = value  # a name or a flag: the style's options check it
        else:
            parse = (_whole if key in ("repeats", "seed") else _number if key in _NUMBERS
                     else parse_fraction if key in _PERCENTS else parse_length)
            style_values[field] = _checked(value, parse, style_ranges[field])
    stitch_options = cls(**style_values)
    if not any(v is not None for v in (size, width, height)):
        size = "90mm"
    placement = _placement(size, width, height, rotate)
    rules = ranges_of(PlanOptions)
    limit = min(_checked(max_stitch, parse_length, rules["max_stitch"]), fmt.max_stitch, profile.max_stitch)
    plan_options = PlanOptions(style=stitch_options, lock=LockOptions(form=lock_form),
                               min_stitch=_checked(min_stitch, parse_length, rules["min_stitch"]),
                               max_stitch=limit,
                               trim_distance=_checked(trim_distance, parse_length, rules["trim_distance"]),
                               min_stroke=_checked(min_stroke, parse_length, rules["min_stroke"]),
                               colors=parse_colors(color) if color is not None else (),
                               thread_chart=check_chart(thread_chart) if thread_chart else None,
                               start=parse_start(start) if start is not None else None)
    spm = _checked(spm, _number, ranges_of(EmbroideryJob)["stitches_per_minute"])
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
    from fabrication.laser.gcode_write import FEED, PASSES, POWER, GcodeOptions
    from fabrication.laser.toolpath import TOLERANCE, ToolpathOptions
    from machines.laser_profile import load_laser_profile
    from onestroke.units import parse_fraction, parse_length, parse_speed

    feed_mm = _checked(feed, parse_speed, FEED)
    power_fraction = _checked(power, parse_fraction, POWER)
    tol = _checked(tolerance, parse_length, TOLERANCE)
    passes = _checked(passes, _whole, PASSES)
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
