"""Ink/Stitch-ready SVG: the drawing at its physical size, each path carrying the parameters of
the stitch an embroiderer picked, in Ink/Stitch's own attributes.

Ink/Stitch (an Inkscape extension) reads `inkstitch:*` attributes on each `<path>` and sews the
paths in document order, so the drawing order survives as it is. Our stitch options
(`fabrication.embroidery`'s running, triple and zigzag options) are translated into the names
and units Ink/Stitch's Params dialog shows; tests/bridges/inkstitch_params.toml lists every name we
write with the Ink/Stitch source it was read from, and the tests check each written one
against it. Stitches:

- running / triple: a stroke with `stroke_method` running_stitch (triple: `bean_stitch_repeats`);
- zigzag: a stroke with `stroke_method` zigzag_stitch; its width is the path's stroke width,
  the measured ink width at the design's size;
- satin: a satin column per stretch between sharp corners: two rails half the ink width either
  side of the curve (the width measured along the stroke where the vectorizer gives it),
  both running in the drawing's direction, and rungs across them.
"""

from __future__ import annotations

import numpy as np

from fabrication.embroidery.running import RunningOptions
from fabrication.embroidery.sampling import dense_curve
from fabrication.embroidery.triple import TripleOptions
from fabrication.embroidery.zigzag import ZigzagOptions
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke
from vectorize.svg_write import SvgPath, drawing_to_svg

NAMESPACE = "http://inkstitch.org/namespace"
STITCHES = ("running", "triple", "zigzag", "satin")

# A satin column turns its rails round a corner sharper than this (degrees) into a twist:
# the column is split there, one column per stretch, in drawing order.
SATIN_CORNER = 90.0
# Rails are polylines through points this far apart along the curve (mm): 0.5 mm keeps them
# within 0.02 mm of the offset curve where it bends at a 1.5 mm radius.
RAIL_STEP = 0.5
# Rungs (the stitch direction) this far apart along the column (mm), one at least per column;
# each reaches this fraction of the half width past its rails, so it crosses both.
RUNG_STEP = 2.0
RUNG_OVERHANG = 0.2
# The stroke width the rails are drawn with (mm): thin, like Ink/Stitch's own satin columns.
SATIN_LINE = 0.1


def _mm(value: float) -> str:
    """A length in mm as Ink/Stitch reads it: plain decimal, no trailing zeros."""
    return f"{value:.3f}".rstrip("0").rstrip(".")


def stroke_attributes(stitch: str, options=None) -> tuple[tuple[str, str], ...]:
    """Ink/Stitch's attributes for a stroke sewn as `stitch` ('running', 'triple', 'zigzag').

    options: that style's options (`RunningOptions`, `TripleOptions`, `ZigzagOptions`); None
    for the defaults. A zigzag's width is the path's stroke width, not an attribute.
    """
    if stitch in ("running", "triple"):
        o = options or (RunningOptions() if stitch == "running" else TripleOptions())
        running = (("inkstitch:stroke_method", "running_stitch"),
                   ("inkstitch:running_stitch_length_mm", _mm(o.stitch_length)),
                   ("inkstitch:running_stitch_tolerance_mm", _mm(o.tolerance)))
        # Ink/Stitch's bean repeats count the extra passes, as our triple stitch's repeats do.
        return running + ((("inkstitch:bean_stitch_repeats", str(o.repeats)),) if stitch == "triple" else ())
    if stitch == "zigzag":
        o = options or ZigzagOptions()
        # Both add the pull compensation to the whole width (half each side).
        return (("inkstitch:stroke_method", "zigzag_stitch"),
                ("inkstitch:zigzag_spacing_mm", _mm(o.spacing)),
                ("inkstitch:pull_compensation_mm", _mm(o.pull_compensation)))
    raise InputError(f"Ink/Stitch stroke stitch {stitch!r} is not one of running, triple, zigzag")


def satin_attributes(options: ZigzagOptions) -> tuple[tuple[str, str], ...]:
    """Ink/Stitch's satin-column attributes for our zigzag options (width: the column's)."""
    attributes = [("inkstitch:satin_column", "true"),
                  ("inkstitch:satin_method", "satin_column"),
                  ("inkstitch:zigzag_spacing_mm", _mm(options.spacing)),
                  # Ink/Stitch's satin compensation is per side; ours is on the whole width.
                  ("inkstitch:pull_compensation_mm", _mm(options.pull_compensation / 2)),
                  ("inkstitch:short_stitch_inset", _mm(100 * options.short_stitch_inset)),
                  ("inkstitch:short_stitch_distance_mm", _mm(options.short_stitch_distance))]
    kind = options.underlay_kind
    if kind == "center":
        attributes += [("inkstitch:center_walk_underlay", "true"),
                       ("inkstitch:center_walk_underlay_stitch_length_mm", _mm(options.underlay_stitch_length))]
    elif kind == "edge":
        attributes += [("inkstitch:contour_underlay", "true"),
                       ("inkstitch:contour_underlay_stitch_length_mm", _mm(options.underlay_stitch_length)),
                       ("inkstitch:contour_underlay_inset_mm", _mm(options.underlay_inset))]
    elif kind == "zigzag":
        attributes += [("inkstitch:zigzag_underlay", "true"),
                       ("inkstitch:zigzag_underlay_spacing_mm", _mm(options.underlay_spacing)),
                       ("inkstitch:zigzag_underlay_inset_mm", _mm(options.underlay_inset))]
    return tuple(attributes)


def satin_columns(stroke: Stroke, width: float) -> list[tuple[Stroke, ...]]:
    """The satin columns of `stroke` (mm): per stretch between corners sharper than
    SATIN_CORNER, in drawing order, its sub-paths (rail, rail, rung, rung, ...). The rails lie
    half the ink width either side of the curve: the width measured along the stroke
    (`Stroke.widths`), else `width`."""
    curve = dense_curve(stroke)
    corners = np.flatnonzero(np.abs(curve.turns) > np.radians(SATIN_CORNER))
    cuts = np.concatenate([[0.0], curve.s[corners], [curve.length]])
    columns = []
    for s0, s1 in zip(cuts[:-1], cuts[1:]):
        if s1 - s0 <= 1e-6:
            continue
        s = np.linspace(s0, s1, max(2, int(np.ceil((s1 - s0) / RAIL_STEP)) + 1))
        # Just inside the stretch: at a corner vertex the tangent is that of either side.
        t = curve.t_at(np.clip(s, s0 + 1e-6 * (s1 - s0), s1 - 1e-6 * (s1 - s0)))
        points, tangents = stroke.points_at(t), stroke.tangents_at(t)
        measured = stroke.widths_at(t)
        half = (np.full(len(t), width) if measured is None else measured)[:, None] / 2
        normal = np.c_[-tangents[:, 1], tangents[:, 0]]
        rails = (Stroke.from_polyline(points + half * normal), Stroke.from_polyline(points - half * normal))
        count = max(1, int(round((s1 - s0) / RUNG_STEP)))
        at = np.round((np.arange(count) + 0.5) * (len(s) - 1) / count).astype(int)
        reach = half * (1 + RUNG_OVERHANG)
        rungs = tuple(Stroke.from_polyline(np.array([points[i] + reach[i] * normal[i],
                                                     points[i] - reach[i] * normal[i]])) for i in at)
        columns.append(rails + rungs)
    return columns


def inkstitch_svg(drawing: Drawing, stitch: str) -> str:
    """The SVG text of `drawing` (mm, on its page: `placement.place_on_page`) with Ink/Stitch's
    parameters for `stitch` (one of STITCHES) on every path, in drawing order."""
    if drawing.unit != "mm":
        raise InputError("an Ink/Stitch document is written in mm: place the drawing first")
    if stitch not in STITCHES:
        raise InputError(f"Ink/Stitch stitch {stitch!r} is not one of {', '.join(STITCHES)}")
    if stitch == "satin":
        attributes = satin_attributes(ZigzagOptions(width=drawing.stroke_width))
        attributes += (("stroke-width", _mm(SATIN_LINE)),)
        paths = [SvgPath(column, attributes, s.color)
                 for s in drawing.strokes for column in satin_columns(s, drawing.stroke_width)]
    else:
        attributes = stroke_attributes(stitch)
        paths = [SvgPath((s,), attributes, s.color) for s in drawing.strokes]
    return drawing_to_svg(drawing, namespaces={"inkstitch": NAMESPACE}, paths=paths)
