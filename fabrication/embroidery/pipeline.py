"""The whole embroidery job as one call: place, hoop, stitch, check, measure.

`embroider(drawing, job)` takes a drawing in any unit and returns the stitch plan, its
stats and what happened on the way (warnings, the fit scale); writing the file and the
preview stay separate calls (`write_embroidery`, `render_stitch_preview`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fabrication.embroidery.hooping import check_plan_in_hoop, fit_to_hoop
from fabrication.embroidery.plan import PlanOptions, StitchPlan, plan_embroidery, style_reach
from fabrication.embroidery.stats import EmbroideryStats, embroidery_stats
from fabrication.embroidery.zigzag import ZigzagOptions
from fabrication.placement import PlacementOptions, place
from machines.hoops import Hoop, hoop_named
from onestroke.errors import InputError
from vectorize.drawing import Drawing


@dataclass(frozen=True, kw_only=True)
class EmbroideryJob:
    """placement: size and rotation of the curve (mm); hoop: the sewing field; fit: scale
    a design that does not fit down instead of refusing it; plan: stitch style and
    design-wide rules; stitches_per_minute / trim_seconds: the machine, for the time."""

    placement: PlacementOptions = field(default_factory=lambda: PlacementOptions(size=90.0))
    hoop: Hoop = field(default_factory=lambda: hoop_named("100x100"))
    fit: bool = False
    plan: PlanOptions = field(default_factory=PlanOptions)
    stitches_per_minute: float = 600.0
    trim_seconds: float = 10.0

    def __post_init__(self) -> None:
        if not self.stitches_per_minute > 0:
            raise InputError(f"stitches per minute {self.stitches_per_minute:g} must be greater than zero")
        if not self.trim_seconds >= 0:
            raise InputError(f"trim time {self.trim_seconds:g} s must be >= 0")


@dataclass(frozen=True, eq=False)
class EmbroideryResult:
    """drawing: the curves as sewn (mm, centred); plan; stats; fit_scale: the factor --fit
    applied (1.0 when it fitted as placed); warnings: one-line messages for the user."""

    drawing: Drawing
    plan: StitchPlan
    stats: EmbroideryStats
    hoop: Hoop
    fit_scale: float
    warnings: tuple[str, ...]


def embroider(drawing: Drawing, job: EmbroideryJob = EmbroideryJob()) -> EmbroideryResult:
    """Place `drawing`, fit it to the hoop, stitch it and measure the result."""
    warnings: list[str] = []
    placed = place(drawing, job.placement)
    hooped = fit_to_hoop(placed, job.hoop, reach=style_reach(job.plan.style), fit=job.fit)
    scale = 1.0
    if hooped is not placed:
        x0, y0, x1, y1 = hooped.bounds()
        px0, _, px1, _ = placed.bounds()
        scale = (x1 - x0) / max(px1 - px0, 1e-12)
        warnings.append(f"scaled down to {x1 - x0:.1f} x {y1 - y0:.1f} mm to fit hoop {job.hoop.label}")
    style = job.plan.style
    if isinstance(style, ZigzagOptions):
        if style.width < 1.0:
            warnings.append(f"a zigzag {style.width:g} mm wide hardly shows; the triple style sews a bold line")
        elif style.width > 7.0:
            warnings.append(f"zigzag stitches {style.width:g} mm wide lie loose and snag; "
                            f"they are split only above {job.plan.max_stitch:g} mm")
    plan = plan_embroidery(hooped, job.plan)
    check_plan_in_hoop(plan, job.hoop)
    if plan.skipped:
        warnings.append(f"{plan.skipped} stroke(s) shorter than the minimum stitch were left out")
    stats = embroidery_stats(plan, stitches_per_minute=job.stitches_per_minute,
                             trim_seconds=job.trim_seconds)
    warnings.extend(stats.warnings)
    return EmbroideryResult(drawing=hooped, plan=plan, stats=stats, hoop=job.hoop,
                            fit_scale=float(scale), warnings=tuple(warnings))
