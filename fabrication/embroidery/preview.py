"""Previews that tell the truth: every needle-down stitch as thread coloured from start
(blue) to end (red) along the curve, every needle point, jumps dashed, trims marked with
a red cross, the hoop outline and the stats in a corner. Also drawings (.svg/.json):
strokes coloured along their parameter.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.canvas import Canvas, check_preview_path, gradient
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, StitchPlan
from fabrication.embroidery.stats import EmbroideryStats
from machines.hoops import Hoop
from onestroke.errors import InputError
from vectorize.drawing import Drawing

THREAD_WIDTH = 0.35  # mm: a 40 wt embroidery thread
# Thread is drawn slightly see-through so that layers sewn over each other (triple stitch,
# locks, overlapping zigs) show darker, as they do on fabric.
THREAD_OPACITY = 0.7
NEEDLE_RADIUS = 0.12  # mm
JUMP_COLOR = (110, 110, 110)
TRIM_COLOR = (220, 30, 30)
HOOP_COLOR = (90, 90, 90)


@dataclass(frozen=True, kw_only=True)
class PreviewOptions:
    """width: image width in px (height follows the aspect ratio of the field shown);
    margin: mm around the hoop or design; needles: draw needle points; stats: draw the
    stats box."""

    width: int = 1000
    margin: float = 4.0
    needles: bool = True
    stats: bool = True

    def __post_init__(self) -> None:
        if not (isinstance(self.width, int) and 64 <= self.width <= 8000):
            raise InputError(f"preview width {self.width!r} px must be an integer from 64 to 8000")
        if not self.margin >= 0:
            raise InputError(f"preview margin {self.margin:g} mm must be >= 0")


def _view(boxes: list[tuple[float, float, float, float]], margin: float) -> tuple[float, float, float, float]:
    b = np.array(boxes, dtype=float)
    xmin, ymin = b[:, 0].min() - margin, b[:, 1].min() - margin
    xmax, ymax = b[:, 2].max() + margin, b[:, 3].max() + margin
    if xmax - xmin < 1e-6:
        xmin, xmax = xmin - 1, xmax + 1
    if ymax - ymin < 1e-6:
        ymin, ymax = ymin - 1, ymax + 1
    return float(xmin), float(ymin), float(xmax), float(ymax)


def stitch_canvas(plan: StitchPlan, *, hoop: Hoop | None = None, stats: EmbroideryStats | None = None,
                  options: PreviewOptions = PreviewOptions()) -> Canvas:
    """The preview of `plan` as a `Canvas` (save it as .png or .svg)."""
    boxes = [plan.bounds()]
    if hoop is not None:
        boxes.append((-hoop.width / 2, -hoop.height / 2, hoop.width / 2, hoop.height / 2))
    canvas = Canvas.fitting(_view(boxes, options.margin), options.width)
    if hoop is not None:
        canvas.rectangle(boxes[-1], HOOP_COLOR, 2.0)
        tick = min(hoop.width, hoop.height) * 0.02
        canvas.segments(np.array([[-tick, 0], [0, -tick]]), np.array([[tick, 0], [0, tick]]),
                        np.tile(HOOP_COLOR, (2, 1)), 0.0, min_px=1.0)
    kinds, points = plan.kinds, plan.points
    # Jumps: from where the needle was to the jump target (a split jump draws as one line).
    jump = np.flatnonzero(kinds == JUMP)
    if len(jump):
        start = jump[np.concatenate([[True], np.diff(jump) > 1])]
        end = jump[np.concatenate([np.diff(jump) > 1, [True]])]
        from_rows = start - 1
        ok = from_rows >= 0
        canvas.dashed(points[from_rows[ok]], points[end[ok]], JUMP_COLOR, 0.15, 1.0)
    a, b = plan.stitches()
    stitch_end = np.flatnonzero(plan.stitch_mask)
    params = plan.params[stitch_end]
    finite = np.isfinite(params)
    lo, hi = (params[finite].min(), params[finite].max()) if finite.any() else (0.0, 1.0)
    u = (params - lo) / max(hi - lo, 1e-12)
    canvas.segments(a, b, gradient(u), THREAD_WIDTH, opacity=THREAD_OPACITY)
    needles = points[kinds == STITCH]
    if options.needles and len(needles):
        canvas.dots(needles, (25, 25, 25), NEEDLE_RADIUS)
    trims = points[kinds == TRIM]
    if len(trims):
        canvas.crosses(trims, TRIM_COLOR, max(10.0, options.width / 60))
    if len(needles):
        canvas.dots(needles[:1], (0, 160, 60), 0.3, min_px=3)  # start
    if options.stats and stats is not None:
        lines = list(stats.lines())
        if hoop is not None:
            lines.append(f"hoop      {hoop.label}")
        lines.append("colour    start blue -> end red")
        canvas.text_box(lines, swatch=plan.color, avoid=plan.points)
    return canvas


def render_stitch_preview(plan: StitchPlan, path: str | os.PathLike, *, hoop: Hoop | None = None,
                          stats: EmbroideryStats | None = None,
                          options: PreviewOptions = PreviewOptions()) -> None:
    """Write the preview of `plan` to `path` (.png or .svg), atomically."""
    check_preview_path(path)
    stitch_canvas(plan, hoop=hoop, stats=stats, options=options).save(path)


def render_drawing_preview(drawing: Drawing, path: str | os.PathLike,
                           options: PreviewOptions = PreviewOptions()) -> None:
    """Write a preview of `drawing`'s strokes, coloured along the drawing order, to `path`."""
    check_preview_path(path)
    if not drawing.strokes:
        raise InputError("the drawing has no strokes to preview")
    xmin, ymin, xmax, ymax = drawing.bounds()
    size = max(xmax - xmin, ymax - ymin, 1e-9)
    margin = size * 0.03
    canvas = Canvas.fitting(_view([(xmin, ymin, xmax, ymax)], margin), options.width)
    tolerance = size / options.width / 4  # a quarter pixel
    a_parts, b_parts, u_parts = [], [], []
    for index, stroke in enumerate(drawing.strokes):
        poly = stroke.flatten(tolerance)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])
        a_parts.append(poly[:-1])
        b_parts.append(poly[1:])
        u_parts.append(index + s[1:] / max(s[-1], 1e-12))
    u = np.concatenate(u_parts) / len(drawing.strokes)
    width = max(drawing.stroke_width, 0.0)
    canvas.segments(np.concatenate(a_parts), np.concatenate(b_parts), gradient(u), width, min_px=2.0)
    starts = np.array([s.start for s in drawing.strokes])
    canvas.dots(starts, (0, 160, 60), size * 0.006, min_px=3)
    if options.stats:
        canvas.text_box([f"strokes   {len(drawing.strokes)}",
                         f"length    {drawing.length:.1f} {drawing.unit}",
                         f"size      {xmax - xmin:.1f} x {ymax - ymin:.1f} {drawing.unit}",
                         "colour    start blue -> end red"],
                        avoid=np.concatenate(a_parts))
    canvas.save(path)
