"""Stitch previews in two styles, drawn through the shared `Canvas`.

realistic (default): every needle-down stitch as thread in its colour, about 0.4 mm wide
with a soft shadow and a light highlight along it, on a fabric-coloured background,
framed to the design with a small margin (the hoop only when asked).
diagnostic: the truth for checking a plan: every needle-down stitch coloured from start
(blue) to end (red) along the curve, every needle point, jumps dashed, trims marked with
a red cross, the hoop outline and the stats in a corner.
Also drawings (.svg/.json): strokes coloured along their parameter.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.canvas import Canvas, check_preview_path, gradient
from fabrication.embroidery.needles import UNDERLAY
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, StitchPlan
from fabrication.embroidery.stats import EmbroideryStats
from machines.hoops import Hoop
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing
from vectorize.stroke import arc_lengths

THREAD_WIDTH = 0.35  # mm: a 40 wt embroidery thread
# Thread is drawn slightly see-through so that layers sewn over each other (triple stitch,
# locks, overlapping zigs) show darker, as they do on fabric.
THREAD_OPACITY = 0.7
NEEDLE_RADIUS = 0.12  # mm
JUMP_COLOR = (110, 110, 110)
TRIM_COLOR = (220, 30, 30)
HOOP_COLOR = (90, 90, 90)
PREVIEW_STYLES = ("realistic", "diagnostic")
PREVIEW_WIDTH = Range(64, 8000, unit="px", name="--preview-width", integer=True)
MARGIN = Range(0.0, None, unit="mm", name="preview margin")
# Realistic style: a 40 wt thread lies about 0.4 mm wide; light comes from the top left.
REAL_THREAD_WIDTH = 0.4
FABRIC_COLOR = (233, 226, 211)  # unbleached cotton
_LIGHT = np.array([-1.0, -1.0]) / np.sqrt(2.0)


@dataclass(frozen=True, kw_only=True)
class PreviewOptions:
    """width: image width in px (height follows the aspect ratio of the field shown);
    margin: mm around the hoop or design; needles: draw needle points; stats: draw the
    stats box (diagnostic style); style: 'realistic' or 'diagnostic'; hoop: draw the
    hoop outline when one is given (the diagnostic style always does)."""

    width: int = ranged(1000, PREVIEW_WIDTH)
    margin: float = ranged(4.0, MARGIN)
    needles: bool = True
    stats: bool = True
    style: str = "realistic"
    hoop: bool = False

    def __post_init__(self) -> None:
        check_ranges(self)
        if self.style not in PREVIEW_STYLES:
            raise InputError(f"preview style {self.style!r} is not one of {', '.join(PREVIEW_STYLES)}")


def _view(boxes: list[tuple[float, float, float, float]], margin: float) -> tuple[float, float, float, float]:
    b = np.array(boxes, dtype=float)
    xmin, ymin = b[:, 0].min() - margin, b[:, 1].min() - margin
    xmax, ymax = b[:, 2].max() + margin, b[:, 3].max() + margin
    if xmax - xmin < 1e-6:
        xmin, xmax = xmin - 1, xmax + 1
    if ymax - ymin < 1e-6:
        ymin, ymax = ymin - 1, ymax + 1
    return float(xmin), float(ymin), float(xmax), float(ymax)


def _shade(colors: np.ndarray, toward: float, amount: float) -> np.ndarray:
    """Colours (S, 3) mixed with grey level `toward` (0 black, 255 white) by `amount`."""
    return np.rint(colors * (1.0 - amount) + toward * amount).astype(np.uint8)


def realistic_canvas(plan: StitchPlan, *, hoop: Hoop | None = None,
                     options: PreviewOptions = PreviewOptions()) -> Canvas:
    """Thread on fabric: each stitch in its thread's colour with shadow and highlight."""
    boxes = [plan.bounds()]
    show_hoop = hoop is not None and options.hoop
    if show_hoop:
        boxes.append((-hoop.width / 2, -hoop.height / 2, hoop.width / 2, hoop.height / 2))
    x0, y0, x1, y1 = boxes[0]
    # A small margin around the design: 6 % of its size, at least 2 mm.
    margin = max(2.0, 0.06 * max(x1 - x0, y1 - y0))
    canvas = Canvas.fitting(_view(boxes, margin), options.width, background=FABRIC_COLOR)
    if show_hoop:
        canvas.rectangle(boxes[-1], HOOP_COLOR, 2.0)
    a, b = plan.stitches()
    if not len(a):
        return canvas
    end = np.flatnonzero(plan.stitch_mask)
    palette = np.array([t.color for t in plan.threads], dtype=float).reshape(-1, 3)
    colors = palette[np.clip(plan.blocks[end], 0, len(palette) - 1)]
    # The highlight runs along the lit edge of each stitch (the side facing the light).
    d = b - a
    length = np.maximum(np.linalg.norm(d, axis=1), 1e-9)
    n = np.column_stack([-d[:, 1], d[:, 0]]) / length[:, None]
    n *= np.where(n @ _LIGHT >= 0, 1.0, -1.0)[:, None]
    lit = n * (REAL_THREAD_WIDTH * 0.18)
    column = _column_stitches(d, end)
    # A column stitch (satin, zigzag: the thread turns back at both ends) goes into the fabric
    # at its rails, square, and ends half a thread short of them: no round cap, which piles a
    # blob on every rail, and no corner poking past the edge.
    trim = np.where(column, np.minimum(0.5 * REAL_THREAD_WIDTH, 0.25 * length), 0.0)[:, None] * d / length[:, None]
    a, b = a + trim, b - trim
    # Stitches are drawn in sewing order, so later thread lies on top, as on fabric.
    for part, caps in ((~column, True), (column, False)):
        if part.any():
            canvas.segments(a[part] + 0.04, b[part] + 0.06, _shade(colors[part], 40, 0.55),
                            REAL_THREAD_WIDTH * 1.15, opacity=0.35, round_caps=caps)
    _threads(canvas, a, b, colors, column)
    # Shorten the highlight so the thread's ends stay matte, like a twisted thread. Across a
    # column the highlights line up into the satin's sheen, brightest where the stitches lie
    # across the light, as a satin ribbon shines. Underlay lies under the top: no highlight.
    top = plan.roles[end] != UNDERLAY
    inset = np.where(column[:, None], 0.12, 0.2) * (b - a)
    across = np.abs(d[:, 0] * _LIGHT[1] - d[:, 1] * _LIGHT[0]) / length
    strength = np.where(column, 0.25 + 0.45 * across, 0.45)
    for level in (0.3, 0.5, 0.7):  # three tones: one draw call each
        part = top & (np.abs(strength - level) <= 0.1 + 1e-9)
        if part.any():
            width = np.where(column[part].any(), 0.4, 0.3) * REAL_THREAD_WIDTH
            canvas.segments(a[part] + lit[part] + inset[part], b[part] + lit[part] - inset[part],
                            _shade(colors[part], 255, level), width, opacity=0.7, min_px=0.6)
    return canvas


def _column_stitches(d: np.ndarray, end: np.ndarray) -> np.ndarray:
    """(S,) True for stitches (directions `d` (S, 2), ending at rows `end`) whose thread turns
    back sharply (more than 120 degrees) at both ends: the rows of a satin or zigzag."""
    unit = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
    back = np.zeros(len(d) + 1, dtype=bool)  # back[i]: stitch i - 1 turns sharply into stitch i
    joined = np.zeros(len(d) + 1, dtype=bool)
    joined[1:-1] = end[1:] - 1 == end[:-1]  # consecutive stitches share a needle point
    back[1:-1] = joined[1:-1] & (np.einsum("ij,ij->i", unit[1:], unit[:-1]) < -0.5)
    return back[:-1] & back[1:]


def _threads(canvas: Canvas, a, b, colors, column) -> None:
    """The threads themselves, in sewing order: round ends on walks, square on columns."""
    breaks = np.flatnonzero(np.diff(column.astype(np.int8))) + 1
    for lo, hi in zip(np.concatenate([[0], breaks]), np.concatenate([breaks, [len(a)]])):
        canvas.segments(a[lo:hi], b[lo:hi], colors[lo:hi].astype(np.uint8), REAL_THREAD_WIDTH,
                        round_caps=not column[lo])


def stitch_canvas(plan: StitchPlan, *, hoop: Hoop | None = None, stats: EmbroideryStats | None = None,
                  options: PreviewOptions = PreviewOptions()) -> Canvas:
    """The preview of `plan` as a `Canvas` (save it as .png or .svg), in `options.style`."""
    if options.style == "realistic":
        return realistic_canvas(plan, hoop=hoop, options=options)
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
        s = arc_lengths(poly)
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
