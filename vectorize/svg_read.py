"""SVG input through svgelements: stroked paths become strokes, filled outlines become ink.

A line drawing stored as SVG comes in one of two forms:
- strokes: paths, lines and polylines drawn with a stroke; each sub-path becomes one
  `Stroke`, in document order, with every transform applied;
- an outline: the ink shape's contour, filled and not stroked (common on stock sites).
  It has no centre line yet; `read_svg` returns its polygons and the vectorizer finds
  the centre-line curve from a rasterization of them.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import svgelements as se

from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


@dataclass(frozen=True)
class SvgContent:
    """What an SVG file holds: stroked curves, filled outline rings, or both.

    `strokes` in document order (px, 96 dpi, y down); `outline_rings` is a tuple of
    (N, 2) closed polylines of filled shapes; `width`/`height` the viewport in px.
    """

    strokes: tuple[Stroke, ...]
    outline_rings: tuple[np.ndarray, ...]
    width: float
    height: float
    stroke_width: float

    @property
    def is_outline(self) -> bool:
        """True when the file is a filled outline drawing with no stroked curves."""
        return not self.strokes and bool(self.outline_rings)

    def as_drawing(self) -> Drawing:
        """The stroked curves as a `Drawing` in px."""
        return Drawing(self.strokes, self.width, self.height, "px", self.stroke_width)


def _segment_control(segment) -> np.ndarray | None:
    """Control points (4, 2) of one svgelements segment as a cubic, or None for a move."""
    if isinstance(segment, se.CubicBezier):
        pts = [segment.start, segment.control1, segment.control2, segment.end]
        return np.array([[p.x, p.y] for p in pts], dtype=float)
    if isinstance(segment, se.QuadraticBezier):
        p0, q, p3 = (np.array([p.x, p.y], dtype=float) for p in (segment.start, segment.control, segment.end))
        return np.array([p0, p0 + 2 / 3 * (q - p0), p3 + 2 / 3 * (q - p3), p3])
    if isinstance(segment, (se.Line, se.Close)):
        if segment.start is None or segment.end is None:
            return None
        a = np.array([segment.start.x, segment.start.y], dtype=float)
        b = np.array([segment.end.x, segment.end.y], dtype=float)
        return np.array([a, a + (b - a) / 3, a + 2 * (b - a) / 3, b])
    return None


def _subpaths(path: se.Path) -> list[np.ndarray]:
    """Cubic control arrays (K, 4, 2), one per sub-path, zero-length pieces dropped."""
    result: list[np.ndarray] = []
    current: list[np.ndarray] = []
    for segment in path:
        if isinstance(segment, se.Move):
            if current:
                result.append(np.array(current))
            current = []
            continue
        if isinstance(segment, se.Arc):
            pieces = [_segment_control(c) for c in segment.as_cubic_curves()]
        else:
            pieces = [_segment_control(segment)]
        for piece in pieces:
            if piece is not None and np.ptp(piece, axis=0).max() > 1e-9:
                current.append(piece)
    if current:
        result.append(np.array(current))
    return result


def _has_paint(value) -> bool:
    return value is not None and getattr(value, "value", None) is not None and value.value != "none" \
        and getattr(value, "opacity", 1.0) != 0


def _rgb(paint) -> tuple[int, int, int] | None:
    """RGB 0-255 of an svgelements paint (the stroke colour), None when it has none."""
    try:
        return int(paint.red), int(paint.green), int(paint.blue)
    except (AttributeError, TypeError, ValueError):
        return None


def read_svg(path: str | os.PathLike) -> SvgContent:
    """Parse an SVG file into strokes and outline rings (px at 96 dpi, transforms applied)."""
    if not os.path.isfile(path):
        raise InputError(f"input file {str(path)!r} does not exist")
    try:
        svg = se.SVG.parse(str(path), reify=True)
    except Exception as error:  # svgelements raises many kinds on malformed XML
        raise InputError(f"cannot read SVG {str(path)!r}: {str(error).splitlines()[0] if str(error) else type(error).__name__}") from None
    strokes: list[Stroke] = []
    rings: list[np.ndarray] = []
    widths: list[float] = []
    for element in svg.elements():
        if not isinstance(element, se.Shape) or isinstance(element, se.Text):
            continue
        if element.values.get("visibility") == "hidden" or element.values.get("display") == "none":
            continue
        path_obj = se.Path(element)
        stroked = _has_paint(element.stroke)
        filled = _has_paint(element.fill)
        color = _rgb(element.stroke) if stroked else None
        for control in _subpaths(path_obj):
            if stroked or not filled:
                # Unpainted shapes are treated as strokes: a line drawing has no other use.
                strokes.append(Stroke(control, color))
                width = element.stroke_width
                widths.append(float(width) if width else 1.0)
            else:
                ring = Stroke(control).flatten(0.05)
                if len(ring) >= 3:
                    rings.append(ring)
    width = float(svg.width) if svg.width else 0.0
    height = float(svg.height) if svg.height else 0.0
    if not strokes and not rings:
        raise InputError(f"SVG {str(path)!r} holds no paths, lines or shapes to use")
    if not (width > 0 and height > 0):
        everything = np.vstack([s.flatten(0.5) for s in strokes] + rings)
        width, height = (float(v) + 1.0 for v in everything.max(axis=0))
    return SvgContent(
        strokes=tuple(strokes),
        outline_rings=tuple(rings),
        width=width,
        height=height,
        stroke_width=float(np.median(widths)) if widths else 1.0,
    )
