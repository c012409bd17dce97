"""The whole embroidery job as one call: place, hoop, stitch, check, measure.

`embroider(drawing, job)` takes a drawing in any unit and returns the stitch plan, its
stats and what happened on the way (warnings, the fit scale); writing the file and the
preview stay separate calls (`write_embroidery`, `render_stitch_preview`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

import numpy as np

from fabrication.embroidery.hooping import check_plan_in_hoop, hoop_design
from fabrication.embroidery.arrows import ArrowOptions
from fabrication.embroidery.needles import BODY, MOTIF
from fabrication.embroidery.plan import FIXED_DATE, PlanOptions, StitchPlan, plan_embroidery, style_reach
from fabrication.embroidery.quality import HOLE_GAP, HOLE_WINDOW, hole_places, repeated_holes, where
from fabrication.embroidery.stats import EmbroideryStats, embroidery_stats
from fabrication.embroidery.triple import TripleOptions
from fabrication.embroidery.satin import SatinOptions
from fabrication.embroidery.zigzag import ZigzagOptions
from fabrication.placement import PlacementOptions, place
from machines.hoops import SPM, Hoop, hoop_named
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing


TRIM_SECONDS = Range(0.0, None, unit="s", name="trim time")
# A budget, not a range of sizes: the work of stitching grows with the steps along the curve
# (curve length over the style's spacing or stitch length). The studio sets one
# (`fabrication.studio.budgets`); the CLI and batch leave it unset.
MAX_STEPS = Range(1, None, name="max_steps", integer=True)

@dataclass(frozen=True, kw_only=True)
class EmbroideryJob:
    """placement: size and rotation of the curve (mm); hoop: the sewing field; fit: scale
    a design that does not fit down instead of refusing it; plan: stitch style and
    design-wide rules; stitches_per_minute / trim_seconds: the machine, for the time;
    name: the design name files store (PES, DST); date: YYYYMMDDhhmmss stored in JEF
    (fixed by default so that files are the same bytes every run); max_steps: refuse
    (`InputError`, before stitching) a design with more steps along its curve than this
    (`steps_along`; None: no limit)."""

    placement: PlacementOptions = field(default_factory=lambda: PlacementOptions(size=90.0))
    hoop: Hoop = field(default_factory=lambda: hoop_named("100x100"))
    fit: bool = False
    plan: PlanOptions = field(default_factory=PlanOptions)
    stitches_per_minute: float = ranged(600.0, SPM)
    trim_seconds: float = ranged(10.0, TRIM_SECONDS)
    name: str = "onestroke"
    date: str = FIXED_DATE
    max_steps: int | None = ranged(None, MAX_STEPS)

    def __post_init__(self) -> None:
        check_ranges(self)
        if not re.fullmatch(r"\d{14}", str(self.date)):
            raise InputError(f"date {self.date!r} must be YYYYMMDDhhmmss")


@dataclass(frozen=True, eq=False)
class EmbroideryResult:
    """drawing: the curves as sewn (mm; the stitches' bounding box centred on (0, 0)); plan;
    stats; fit_scale: the factor --fit applied (1.0 when it fitted as placed or turned);
    turned: --fit turned the design a quarter counter-clockwise (as --rotate 90) to fit
    without scaling; warnings: one-line messages for the user."""

    drawing: Drawing
    plan: StitchPlan
    stats: EmbroideryStats
    hoop: Hoop
    fit_scale: float
    warnings: tuple[str, ...]
    turned: bool = False


def embroider(drawing: Drawing, job: EmbroideryJob = EmbroideryJob(), *, progress=None) -> EmbroideryResult:
    """Place `drawing`, fit it to the hoop, stitch it and measure the result.
    progress: an `onestroke.progress.ProgressCallback` (strokes stitched)."""
    warnings: list[str] = []
    placed = place(drawing, job.placement)
    fitted = hoop_design(placed, job.hoop, reach=style_reach(job.plan.style, placed), fit=job.fit)
    hooped = fitted.drawing
    x0, y0, x1, y1 = hooped.bounds()
    if fitted.turned:
        warnings.append(f"turned by 90 degrees (as --rotate 90 would) to fit hoop {job.hoop.label} "
                        f"without scaling: {x1 - x0:.1f} x {y1 - y0:.1f} mm")
    elif fitted.scale != 1.0:
        warnings.append(f"scaled down to {x1 - x0:.1f} x {y1 - y0:.1f} mm to fit hoop {job.hoop.label}")
    style = job.plan.style
    if isinstance(style, ZigzagOptions) and style.width < 1.0:
        warnings.append(f"a zigzag {style.width:g} mm wide hardly shows; the triple style sews a bold line")
    if isinstance(style, ZigzagOptions) and style.width > LOOSE_ZIGZAG:
        warnings.append(f"zigzag stitches {style.width:g} mm wide lie loose and snag (over "
                        f"{LOOSE_ZIGZAG:g} mm); use a narrower --stitch-width")
    if job.max_steps is not None:
        _check_steps(hooped, style, job.max_steps)
    plan = plan_embroidery(hooped, job.plan, progress=progress, centre=True)
    check_plan_in_hoop(plan, job.hoop)
    warnings.extend(plan.dropped)
    if len(job.plan.colors) > len(drawing.strokes):
        warnings.append(f"--color lists {len(job.plan.colors)} colours for {len(drawing.strokes)} "
                        "stroke(s); the extra colours are unused")
    warnings.extend(_long_stitch_warnings(plan, style))
    plan = replace(plan, name=job.name, field=(job.hoop.width, job.hoop.height), date=job.date)
    stats = embroidery_stats(plan, stitches_per_minute=job.stitches_per_minute,
                             trim_seconds=job.trim_seconds, density_advice=density_advice(style),
                             column=isinstance(style, COLUMN_STYLES))
    warnings.extend(stats.warnings)
    warnings.extend(_hole_warnings(plan))
    return EmbroideryResult(drawing=plan.sewn, plan=plan, stats=stats, hoop=job.hoop,
                            fit_scale=float(fitted.scale), warnings=tuple(warnings), turned=fitted.turned)


def steps_along(drawing: Drawing, style) -> tuple[float, float, float]:
    """(steps, curve length mm, step mm): how many rows, arrows or stitches `style` makes
    along the strokes of `drawing` (mm) at its shortest step, its spacing or stitch length."""
    step = min(getattr(style, name) for name in ("spacing", "stitch_length") if hasattr(style, name))
    length = float(sum(stroke.length for stroke in drawing.strokes))
    return length / step, length, step


def _check_steps(drawing: Drawing, style, limit: int) -> None:
    steps, length, step = steps_along(drawing, style)
    if steps > limit:
        option = "--spacing" if hasattr(style, "spacing") else "--stitch-length"
        raise InputError(f"{step:g} mm steps along {length:,.0f} mm of curve are {steps:,.0f} steps, more than "
                         f"the {limit:,} an interactive preview makes; use a {'wider' if option == '--spacing' else 'longer'} "
                         f"{option} or a smaller --size")


# Styles whose body stitches cross a column (the bobbin shows only in its middle third).
COLUMN_STYLES: tuple[type, ...] = (ZigzagOptions, SatinOptions)


def density_advice(style) -> str:
    """What to change where a design of `style` is too dense (its own options first)."""
    for kind, advice in _DENSITY_ADVICE.items():
        if isinstance(style, kind):
            return advice
    return "use a longer --stitch-length or a larger --size"


_DENSITY_ADVICE = {
    ZigzagOptions: "use a wider --spacing, --underlay none or a larger --size",
    SatinOptions: "use a wider --spacing, --underlay none, a smaller --width-scale or a larger --size",
    ArrowOptions: "use a wider --spacing, a smaller --arrow-size or a larger --size",
    TripleOptions: "use a longer --stitch-length, --style running or a larger --size",
}


def _hole_warnings(plan: StitchPlan) -> list[str]:
    """A warning naming the places where a needle re-enters a hole it made a moment before."""
    rows = repeated_holes(plan)
    if not len(rows):
        return []
    return [f"{len(rows)} needle points re-enter a hole made a moment before (within {HOLE_GAP:g} mm of "
            f"one of the last {HOLE_WINDOW} on their side of the line) {where(hole_places(plan, rows))}; "
            "the thread there may be cut or pile up; a larger --size or another --style avoids it"]


# Stitches longer than this (mm) lie loose on the fabric and snag; zigzags wider than
# LOOSE_ZIGZAG likewise (satin columns are split above about 7-10 mm).
LOOSE_STITCH = 7.0
LOOSE_ZIGZAG = 10.0


def _long_stitch_warnings(plan: StitchPlan, style) -> list[str]:
    """A warning when body or motif stitches (not zigzag, warned by width) exceed
    LOOSE_STITCH, naming the option that makes them."""
    if isinstance(style, ZigzagOptions):
        return []
    a, b = plan.stitches()
    end = np.flatnonzero(plan.stitch_mask)
    role = plan.roles[end]
    length = np.linalg.norm(b - a, axis=1)
    loose = ((role == BODY) | (role == MOTIF)) & (length > LOOSE_STITCH + 1e-9)
    if not loose.any():
        return []
    arms = loose & (role == MOTIF)
    if isinstance(style, ArrowOptions) and arms.any():
        option = "a smaller --arrow-size or --stitch-width"
    else:
        option = "a shorter --stitch-length"
    return [f"{int(loose.sum())} stitches are longer than {LOOSE_STITCH:g} mm (up to "
            f"{float(length[loose].max()):.1f} mm): they lie loose and snag; use {option}"]
