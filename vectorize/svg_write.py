"""SVG and JSON output of a `Drawing`: one `<path>` per stroke, in drawing order."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from onestroke.atomic import atomic_write_text
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _quoted(value: str) -> str:
    """`xml.sax.saxutils.quoteattr(value)`: an attribute value in quotes, escaped. Plain values
    (numbers, names, URIs) need no escaping and are quoted here without importing saxutils,
    which brings urllib.request, http.client and ssl (~13 ms of every command's start-up)."""
    if not any(char in value for char in '&<>"\n\r\t'):
        return f'"{value}"'
    from xml.sax.saxutils import quoteattr

    return quoteattr(value)


def _num(value: float) -> str:
    """Compact, deterministic number: 3 decimals, no trailing zeros, no '-0'."""
    text = f"{value:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def path_data(stroke: Stroke) -> str:
    """SVG path data "M x y C x1 y1 x2 y2 x y ..." of one stroke (Z when closed)."""
    c = stroke.control
    parts = [f"M{_num(c[0, 0, 0])} {_num(c[0, 0, 1])}"]
    for seg in c:
        parts.append("C" + " ".join(f"{_num(x)} {_num(y)}" for x, y in seg[1:]))
    if stroke.is_closed and len(c) > 1:
        parts.append("Z")
    return "".join(parts)


def widths_data(stroke: Stroke) -> str:
    """A stroke's ink widths as written in `data-widths`: "t w t w ...", t the path's
    parameter (segment k of K spans t in [k/K, (k+1)/K]) to 6 decimals, w the width in the
    drawing's unit to 3."""
    return " ".join(f"{_num6(t)} {_num(w)}" for t, w in stroke.widths)


def _num6(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


@dataclass(frozen=True)
class SvgPath:
    """One `<path>` of the document: its sub-paths in order (one `M` each) and extra attributes.

    attributes: (name, value) pairs written on the element, e.g. ("stroke-width", "0.1") or a
    namespaced ("inkstitch:satin_column", "true") whose prefix `drawing_to_svg` declares;
    color: RGB 0-255 overriding the group's stroke colour, None to inherit it.
    """

    subpaths: tuple[Stroke, ...]
    attributes: tuple[tuple[str, str], ...] = ()
    color: tuple[int, int, int] | None = None


def drawing_to_svg(drawing: Drawing, *, color: str = "#000000", namespaces: Mapping[str, str] | None = None,
                   paths: Sequence[SvgPath] | None = None) -> str:
    """The SVG text of `drawing`: viewBox = its canvas, stroke width = its measured width.

    By default one `<path>` per stroke, in drawing order, each whose ink widths are known
    carrying them in `data-widths` (`widths_data`). `paths` replaces them (the same canvas
    and group style), e.g. with a bridge's parameters on each; `namespaces` (prefix -> URI)
    are declared on the root for their attributes.
    """
    w, h = _num(drawing.width), _num(drawing.height)
    size = f'width="{w}mm" height="{h}mm"' if drawing.unit == "mm" else f'width="{w}" height="{h}"'
    declared = "".join(f" xmlns:{prefix}={_quoted(uri)}" for prefix, uri in (namespaces or {}).items())
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg"{declared} {size} viewBox="0 0 {w} {h}">',
        f'<g fill="none" stroke="{color}" stroke-width="{_num(drawing.stroke_width)}" '
        'stroke-linecap="round" stroke-linejoin="round">',
    ]
    if paths is None:
        paths = [SvgPath((stroke,), () if stroke.widths is None else (("data-widths", widths_data(stroke)),),
                         stroke.color) for stroke in drawing.strokes]
    for index, path in enumerate(paths):
        # A path's own colour overrides the group's; uncoloured paths inherit it.
        paint = "" if path.color is None else ' stroke="#{:02x}{:02x}{:02x}"'.format(*path.color)
        extra = "".join(f" {name}={_quoted(str(value))}" for name, value in path.attributes)
        data = "".join(path_data(sub) for sub in path.subpaths)
        lines.append(f'<path id="stroke-{index + 1}"{paint}{extra} d="{data}"/>')
    lines += ["</g>", "</svg>", ""]
    return "\n".join(lines)


def drawing_to_json(drawing: Drawing) -> str:
    """JSON with the canvas and each stroke's control points, shape (K, 4, 2); "widths"
    (when a stroke has them): one entry per stroke, its `Stroke.widths` rows [t, width] or
    null."""
    payload = {
        "format": "onestroke-drawing",
        "version": 1,
        "unit": drawing.unit,
        "width": round(float(drawing.width), 6),
        "height": round(float(drawing.height), 6),
        "stroke_width": round(float(drawing.stroke_width), 6),
        "strokes": [np.round(s.control, 4).tolist() for s in drawing.strokes],
    }
    if any(s.color is not None for s in drawing.strokes):
        # One entry per stroke: [r, g, b] or null (written only when a stroke has a colour).
        payload["colors"] = [None if s.color is None else list(s.color) for s in drawing.strokes]
    if any(s.widths is not None for s in drawing.strokes):
        payload["widths"] = [None if s.widths is None else np.column_stack([np.round(s.widths[:, 0], 6),
                                                                            np.round(s.widths[:, 1], 4)]).tolist()
                             for s in drawing.strokes]
    return json.dumps(payload, separators=(",", ":")) + "\n"


def _drawing_schema() -> dict:
    """What `drawing_to_json` writes, as `onestroke.json_check` reads it."""
    from vectorize.drawing import UNITS
    from vectorize.stroke import MAX_COORDINATE

    side = {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_COORDINATE}
    rgb = {"type": "array", "minItems": 3, "maxItems": 3, "items": {"type": "integer", "minimum": 0, "maximum": 255}}
    return {"type": "object", "required": ["format", "width", "height", "strokes"], "properties": {
        "format": {"const": "onestroke-drawing"}, "version": {"const": 1}, "unit": {"enum": list(UNITS)},
        "width": side, "height": side, "stroke_width": {"type": "number", "minimum": 0, "maximum": MAX_COORDINATE},
        "strokes": {"type": "array", "items": {"shape": [None, 4, 2]}},
        "colors": {"type": ["array", "null"], "items": {"type": ["array", "null"], **rgb}},
        "widths": {"type": ["array", "null"], "items": {"type": ["array", "null"], "items": {"shape": [2]}}}}}


def drawing_from_json(text: str | bytes, *, name: str = "JSON drawing") -> Drawing:
    """Parse what `drawing_to_json` wrote; `InputError` naming `name` (the file) and what in
    it is wrong (checked against the schema before anything is built)."""
    from onestroke.errors import InputError
    from onestroke.json_check import parse_json

    payload = parse_json(text, _drawing_schema(), what=name)
    strokes = payload["strokes"]
    colors = payload.get("colors") or [None] * len(strokes)
    if len(colors) != len(strokes):
        raise InputError(f"{name}: $.colors: {len(colors)} colours for {len(strokes)} strokes")
    widths = payload.get("widths") or [None] * len(strokes)
    if len(widths) != len(strokes):
        raise InputError(f"{name}: $.widths: {len(widths)} width profiles for {len(strokes)} strokes")
    for index, control in enumerate(strokes):  # a stroke is one curve: each piece starts where the last ended
        control = np.asarray(control, dtype=float)
        gaps = np.flatnonzero(~np.isclose(control[1:, 0], control[:-1, 3], rtol=1e-9, atol=1e-3).all(axis=1))
        if len(gaps):
            raise InputError(f"{name}: $.strokes[{index}][{gaps[0] + 1}] does not start where the piece before it "
                             "ends; a stroke is one connected curve")
    try:
        return Drawing(
            strokes=tuple(Stroke(np.array(c, dtype=float), None if rgb is None else tuple(rgb),
                                 None if w is None else np.array(w, dtype=float))
                          for c, rgb, w in zip(strokes, colors, widths)),
            width=float(payload["width"]),
            height=float(payload["height"]),
            unit=payload.get("unit", "px"),
            stroke_width=float(payload.get("stroke_width", 1.0)),
        )
    except InputError as error:
        raise InputError(f"{name}: {error}") from None


def read_drawing_json(path: str | os.PathLike) -> Drawing:
    """A .json drawing file (`drawing_from_json`), refused in one line when it is not one."""
    from onestroke.paths import check_input_file

    name = check_input_file(path, what="drawing", expect="a .json drawing")
    with open(name, "rb") as handle:
        return drawing_from_json(handle.read(), name=f"drawing {name!r}")


def write_drawing(drawing: Drawing, path: str | os.PathLike) -> None:
    """Write `drawing` atomically as .svg or .json, chosen by the extension."""
    from onestroke.errors import InputError

    suffix = os.path.splitext(str(path))[1].lower()
    if suffix == ".svg":
        atomic_write_text(path, drawing_to_svg(drawing))
    elif suffix == ".json":
        atomic_write_text(path, drawing_to_json(drawing))
    else:
        raise InputError(f"cannot write a drawing as {suffix or 'a file without extension'!r}; use .svg or .json")
