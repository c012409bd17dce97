"""Zigzag across the curve (paper Fig. 13 middle): needle points alternate side to side.

A constant-width column (`fabrication.embroidery.columns`): rows every spacing/2 along the
longer rail, each pushed perpendicular to the local direction by width/2 +
pull_compensation/2, alternating sides. The direction is the chord over +-reach around the
point: the tangent on straight parts and arcs, a fan round a bend. Corners sharper than
`corner_angle` are mitred, or split into two columns that overlap by `overlap` mm where the
mitre would reach past `mitre_limit` half widths (the wave drawing's 150 degree fold): no
spur, no pile-up, no slit. On tight inner curves the inside points crowd: every other
crowded inner point is inset (Ink/Stitch's short stitches: 30 % of the reach where points
on the rail come closer than 0.35 mm) and a point still within `min_gap` of one of the
last two on its rail is inset deeper (`fabrication.embroidery.column_stitches`): no needle
goes into a hole next to one it made a moment before. Zigs longer than `max_stitch` are
split at staggered points. Underlay (sewn first, there and back so the zigzag starts where
the stroke does), as satin columns use: 'center' a walk along the curve (back between the
holes of the way out), 'edge' a walk along each rail inset from the edge, 'zigzag' a
sparse zigzag inset from the edges, out and back in opposite phase; by default a centre
walk once the zigzag is wider than `underlay_min_width`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.column_stitches import ColumnStitching, column_needles
from fabrication.embroidery.columns import CORNER_ANGLE, MITRE_LIMIT, OVERLAP, stroke_columns
from fabrication.embroidery.needles import GRID, NeedlePoints
from fabrication.embroidery.running import DENSE_TOLERANCE, STITCH_LENGTH, TOLERANCE
from fabrication.embroidery.sampling import dense_curve
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import Stroke

# Rail to rail, and the arrows' spread (`arrows.ArrowOptions.width`): one --stitch-width.
STITCH_WIDTH = Range(GRID, 12.0, unit="mm", name="--stitch-width")
# Peak to peak along the curve, and the arrows' tip to tip: one --spacing.
SPACING = Range(GRID, 50.0, unit="mm", name="--spacing")
PULL_COMPENSATION = Range(0.0, 2.0, unit="mm", name="--pull-comp")
UNDERLAY_INSET = Range(0.0, None, unit="mm", name="underlay inset")
UNDERLAY_SPACING = Range(0.5, None, unit="mm", name="underlay spacing")
SHORT_STITCH_INSET = Range(0.0, 1.0, name="short-stitch inset", high_open=True)
ZIG_MAX_STITCH = Range(1.0, None, unit="mm", name="zigzag max stitch", low_open=True)

UNDERLAYS = ("center", "edge", "zigzag", "none")


@dataclass(frozen=True, kw_only=True)
class ZigzagOptions:
    """width: rail to rail in mm; spacing: peak to peak along the curve in mm;
    pull_compensation: mm added to the width (half per side) since the thread pulls the
    fabric in; underlay: 'center', 'edge', 'zigzag' or 'none' (True = 'center', False =
    'none'), None = 'center' when width > underlay_min_width; underlay_inset: how far
    edge and zigzag underlay stay inside the edges, mm; underlay_spacing: peak to peak of
    the zigzag underlay, mm;
    short_stitch_distance / short_stitch_inset: inset every other inner point by this
    fraction of the reach where inner points come closer than that distance; min_gap: the
    closest two needle points may come on one rail (0.35 mm keeps them >= 0.2 mm apart
    after snapping to the files' 0.1 mm grid); max_stitch: longer zigs are split;
    corner_angle (degrees), mitre_limit (half widths), overlap (mm): corners, as satin's
    (`fabrication.embroidery.columns`)."""

    width: float = ranged(2.0, STITCH_WIDTH)
    spacing: float = ranged(0.4, SPACING)
    pull_compensation: float = ranged(0.2, PULL_COMPENSATION)
    underlay: bool | str | None = None
    underlay_min_width: float = 1.5
    underlay_stitch_length: float = ranged(2.0, STITCH_LENGTH.named("underlay stitch length"))
    underlay_inset: float = ranged(0.4, UNDERLAY_INSET)
    underlay_spacing: float = ranged(3.0, UNDERLAY_SPACING)
    short_stitch_distance: float = 0.35
    short_stitch_inset: float = ranged(0.3, SHORT_STITCH_INSET)
    min_gap: float = 0.35
    max_stitch: float = ranged(12.1, ZIG_MAX_STITCH)
    tolerance: float = ranged(0.2, TOLERANCE)
    corner_angle: float = ranged(45.0, CORNER_ANGLE)
    mitre_limit: float = ranged(2.0, MITRE_LIMIT)
    overlap: float = ranged(0.3, OVERLAP)

    def __post_init__(self) -> None:
        check_ranges(self)
        if isinstance(self.underlay, str):
            key = self.underlay.strip().lower().replace("centre", "center")
            if key not in UNDERLAYS:
                raise InputError(f"underlay {self.underlay!r} is not one of {', '.join(UNDERLAYS)}")
            object.__setattr__(self, "underlay", key)
        elif self.underlay is not None and not isinstance(self.underlay, bool):
            raise InputError(f"underlay {self.underlay!r} is not one of {', '.join(UNDERLAYS)}")

    @property
    def reach(self) -> float:
        """Offset of each needle point from the centre line, mm."""
        return (self.width + self.pull_compensation) / 2.0

    @property
    def underlay_kind(self) -> str:
        """'center', 'edge', 'zigzag' or 'none' after the defaults."""
        if self.underlay is None:
            return "center" if self.width > self.underlay_min_width else "none"
        if isinstance(self.underlay, bool):
            return "center" if self.underlay else "none"
        return self.underlay

    @property
    def has_underlay(self) -> bool:
        return self.underlay_kind != "none"


def zigzag_stitch(stroke: Stroke, options: ZigzagOptions = ZigzagOptions()) -> NeedlePoints:
    """Zigzag along `stroke` (mm), preceded by a there-and-back underlay when wide."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)

    def half_at(s: np.ndarray) -> np.ndarray:
        return np.full(len(s), options.reach)

    columns = stroke_columns(stroke, curve, half_at, options.spacing, corner_angle=options.corner_angle,
                             mitre_limit=options.mitre_limit, overlap=options.overlap)
    kind = options.underlay_kind
    # The zigzag's underlay inset counts from the drawn edge, the columns' from the rail.
    inset = options.reach - max(0.0, options.width / 2.0 - options.underlay_inset)
    how = ColumnStitching(
        spacing=options.spacing, short_stitch_distance=options.short_stitch_distance,
        # the zigzag's inset is a share of its reach, the columns' of the row's width (twice it)
        short_stitch_inset=options.short_stitch_inset / 2.0, min_gap=options.min_gap, max_stitch=options.max_stitch,
        underlays=() if kind == "none" else (kind,), underlay_stitch_length=options.underlay_stitch_length,
        edge_inset=inset, zigzag_inset=inset, underlay_spacing=options.underlay_spacing, tolerance=options.tolerance)
    return column_needles(stroke, curve, columns, how)
