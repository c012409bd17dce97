"""SVG input through svgelements: stroked paths become strokes, filled outlines become ink.

A line drawing stored as SVG comes in one of two forms:
- strokes: paths, lines and polylines drawn with a stroke; each sub-path becomes one
  `Stroke`, in document order, with every transform applied;
- an outline: the ink shape's contour, filled and not stroked (common on stock sites).
  It has no centre line yet; `read_svg` returns its polygons and the vectorizer finds
  the centre-line curve from a rasterization of them.

Files from the wild spell the SVG namespace in many ways (https, a trailing slash, none at
all), wrap the drawing in XHTML or come gzip-compressed (.svgz); `vectorize.svg.svg_source`
reads them within bounds (references expanded, nesting, size) before svgelements parses
them. A coordinate that is not finite or lies beyond
`stroke.MAX_COORDINATE` (1e7 px, 260 m at 96 dpi) is refused, naming the element.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import svgelements as se

from onestroke.errors import InputError
from onestroke.paths import check_input_file
from onestroke.progress import ProgressCallback, Stage, counted
from vectorize.drawing import Drawing
from vectorize.stroke import MAX_COORDINATE, Stroke, checked_widths, recut_widths
from vectorize.svg.svg_source import ChunkReader, svg_source


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


def _segment_row(segment) -> tuple[float, ...] | None:
    """Control points of one svgelements segment as a cubic, flat (x0, y0, ..., x3, y3), or
    None for a move. Plain floats: one array per path, not one per segment (a 20,000-path
    file has 60,000 segments or more)."""
    if isinstance(segment, se.CubicBezier):
        a, b, c, d = segment.start, segment.control1, segment.control2, segment.end
        return (a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y)
    if isinstance(segment, se.QuadraticBezier):
        p0, q, p3 = (np.array([p.x, p.y], dtype=float) for p in (segment.start, segment.control, segment.end))
        return tuple(np.array([p0, p0 + 2 / 3 * (q - p0), p3 + 2 / 3 * (q - p3), p3]).ravel())
    if isinstance(segment, (se.Line, se.Close)):
        if segment.start is None or segment.end is None:
            return None
        a = np.array([segment.start.x, segment.start.y], dtype=float)
        b = np.array([segment.end.x, segment.end.y], dtype=float)
        return tuple(np.array([a, a + (b - a) / 3, a + 2 * (b - a) / 3, b]).ravel())
    return None


def _arc_cubics(arc, element, path: str):
    """The cubics of an elliptical arc; `InputError` naming the element when its radii,
    angle or sweep are not finite (`A 1e308 1e308 0 1 1 10 10` overflows to NaN)."""
    values = (arc.rx, arc.ry, arc.sweep, arc.get_rotation())
    if not all(np.isfinite(float(v)) for v in values if v is not None):
        raise InputError(f"SVG {path!r}: {_element_name(element)} has an arc whose radius or sweep is not a finite "
                         "number (radii too large?)")
    return arc.as_cubic_curves()


def _subpaths(path, element, source: str) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """Per sub-path: cubic control array (K, 4, 2) with zero-length pieces dropped, the index
    of each kept piece among the sub-path's drawn pieces (a closing Z's straight piece is not
    one of them) and how many drawn pieces there were. element, source: the SVG element and
    file, for messages."""
    result: list[tuple[np.ndarray, np.ndarray, int]] = []
    current: list[tuple[float, ...]] = []
    closing: list[bool] = []

    def close() -> None:
        if current:
            control = np.array(current, dtype=float).reshape(-1, 4, 2)
            _check_coordinates(control, element, source)  # before NaN pieces look zero-length
            keep = np.ptp(control, axis=1).max(axis=1) > 1e-9
            drawn = ~np.array(closing)
            if keep.any():
                index = np.cumsum(drawn) - 1
                result.append((control[keep], index[keep], int(drawn.sum())))

    for segment in path:
        if isinstance(segment, se.Move):
            close()
            current, closing = [], []
            continue
        if isinstance(segment, se.Arc):
            rows = [_segment_row(c) for c in _arc_cubics(segment, element, source)]
        else:
            rows = [_segment_row(segment)]
        rows = [row for row in rows if row is not None]
        current.extend(rows)
        closing.extend([isinstance(segment, se.Close)] * len(rows))
    close()
    return result


def _widths(element, path: str, index: np.ndarray, drawn: int) -> np.ndarray | None:
    """The `Stroke.widths` of an element's `data-widths` (onestroke's own SVGs: "t w t w ...",
    t the path's parameter over its drawn pieces, w in user units), for the pieces `index`
    kept of `drawn`; None without the attribute. Widths are scaled by the element's
    transform (the viewBox included)."""
    text = element.values.get("data-widths")
    if text is None:
        return None
    try:
        rows = np.array(str(text).replace(",", " ").split(), dtype=float).reshape(-1, 2)
        scale = float(np.sqrt(abs(se.Matrix(element.values.get("transform", "")).determinant)))
        widths = checked_widths(np.column_stack([rows[:, 0], rows[:, 1] * scale]))
    except (ValueError, InputError) as error:
        raise InputError(f"SVG {path!r}: {_element_name(element)} has data-widths that are not "
                         f"(t, width) pairs with t rising from 0 to 1: {error}") from None
    if len(index) == drawn and np.array_equal(index, np.arange(drawn)):
        return widths
    # Pieces of zero length were dropped: the kept pieces' old parameters, in turn.
    old = np.column_stack([index, index + 1]).ravel() / drawn
    kept = np.arange(len(index))
    return recut_widths(widths, old, np.column_stack([kept, kept + 1]).ravel() / len(index))


def _has_paint(value) -> bool:
    return value is not None and getattr(value, "value", None) is not None and value.value != "none" \
        and getattr(value, "opacity", 1.0) != 0


def _element_name(element) -> str:
    """`<circle id="c1">` or `<path>`: how a message names an element."""
    tag = type(element).__name__.lower().replace("simpleline", "line")
    ident = getattr(element, "id", None)
    return f"<{tag} id={ident!r}>" if ident else f"<{tag}>"


def _check_coordinates(control: np.ndarray, element, path: str) -> None:
    if not np.all(np.isfinite(control)):
        raise InputError(f"SVG {path!r}: {_element_name(element)} has a coordinate that is not a finite number")
    largest = float(np.abs(control).max())
    if largest > MAX_COORDINATE:
        raise InputError(f"SVG {path!r}: {_element_name(element)} reaches a coordinate of {largest:.3g} px, "
                         f"beyond the limit of {MAX_COORDINATE:.0e} px")


def _canvas_side(value) -> float:
    """A viewport side in px, or 0 when missing, not finite or beyond the coordinate limit."""
    try:
        side = float(value) if value else 0.0
    except (TypeError, ValueError):
        return 0.0
    return side if np.isfinite(side) and 0 < side <= MAX_COORDINATE else 0.0


def _rgb(paint) -> tuple[int, int, int] | None:
    """RGB 0-255 of an svgelements paint (the stroke colour), None when it has none."""
    try:
        return int(paint.red), int(paint.green), int(paint.blue)
    except (AttributeError, TypeError, ValueError):
        return None


def read_svg(path: str | os.PathLike, *, progress: ProgressCallback | None = None) -> SvgContent:
    """Parse an SVG file (or gzip-compressed .svgz) into strokes and outline rings (px at 96
    dpi, transforms applied), within the bounds of `vectorize.svg.svg_source`.

    progress: called with `onestroke.progress.Progress` reports (bytes read, bytes parsed,
    then shapes read).
    """
    path = check_input_file(path, expect="an SVG file")
    source = svg_source(path, progress=progress)
    try:
        parsing = Stage(progress, "parsing", len(source), "bytes") if progress is not None else None
        svg = se.SVG.parse(ChunkReader(source, parsing), reify=True)
        if parsing is not None:
            parsing.finish()
    except RecursionError:
        raise InputError(f"cannot read SVG {path!r}: it nests too deeply to read") from None
    except Exception as error:  # svgelements raises many kinds on malformed XML
        raise InputError(f"cannot read SVG {path!r}: {str(error).splitlines()[0] if str(error) else type(error).__name__}") from None
    if svg is None:
        raise InputError(f"SVG {path!r}: its root <svg> is hidden (display:none), so nothing in it is drawn; "
                         "remove that style to use the drawing")
    strokes: list[Stroke] = []
    rings: list[np.ndarray] = []
    widths: list[float] = []
    try:
        elements = list(svg.elements())
    except (ValueError, ArithmeticError, AttributeError, TypeError) as error:
        raise InputError(f"cannot read SVG {path!r}: {error}") from None
    for element in counted(elements, progress, "reading shapes", len(elements), "elements"):
        if not isinstance(element, se.Shape) or isinstance(element, se.Text):
            continue
        if element.values.get("visibility") == "hidden" or element.values.get("display") == "none":
            continue
        if isinstance(element, se.Path) and element.transform.is_identity():
            # Its control points are checked below; they bound the curve (the exact bbox of
            # svgelements costs more than reading the path).
            path_obj = element
        else:
            try:
                bbox = element.bbox()
            except (ValueError, ArithmeticError, TypeError):
                bbox = None
            if bbox is not None:
                _check_coordinates(np.asarray(bbox, dtype=float), element, path)
            path_obj = se.Path(element)
        stroked = _has_paint(element.stroke)
        filled = _has_paint(element.fill)
        color = _rgb(element.stroke) if stroked else None
        pieces = _subpaths(path_obj, element, path)
        for control, index, drawn in pieces:
            if stroked or not filled:
                # Unpainted shapes are treated as strokes: a line drawing has no other use.
                profile = _widths(element, path, index, drawn) if len(pieces) == 1 else None
                strokes.append(Stroke(control, color, profile))
                width = element.stroke_width
                widths.append(float(width) if width and np.isfinite(float(width)) else 1.0)
            else:
                ring = Stroke(control).flatten(0.05)
                if len(ring) >= 3:
                    rings.append(ring)
    width = _canvas_side(svg.width)
    height = _canvas_side(svg.height)
    if not strokes and not rings:
        raise InputError(f"SVG {path!r} holds no paths, lines or shapes to use")
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
