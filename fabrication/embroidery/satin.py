"""Satin column along a stroke, as wide as the drawn line.

The column's width follows the ink's width along the stroke (`Stroke.widths`, the
vectorizer's measure, scaled with the design when it was placed) times `width_scale`, held
within [`min_width`, `max_width`]; a constant `width` overrides it, and a stroke whose width
is unknown takes the drawing's. Pull compensation widens every row by `pull_compensation`
mm plus `pull_compensation_percent` of its width (both shared between the two sides; Ink/
Stitch gives each side its own value: ours is the two sides' sum). The other controls and
their defaults are Ink/Stitch's satin column's (short stitches 15 % below 0.25 mm, spacing
0.4 mm, underlays with a 3 mm stitch, contour inset 0.4 mm, zigzag underlay every 3 mm at
half the contour inset), except where noted:

- underlay 'auto' (Ink/Stitch has none unless asked): none below 1 mm, a centre walk for
  columns up to 2 mm wide, an edge walk to 4 mm, edge walk and zigzag underlay ("German underlay") above,
  judged on the stroke's median width (the rule of thumb digitizers use);
- max_stitch_length 7 mm (Ink/Stitch: no limit): wider rows are split, since a longer
  stitch lies loose (the planner's LOOSE_STITCH);
- corners (`fabrication.embroidery.columns`): turns sharper than `corner_angle` within a
  half width are mitred while the mitre stays within `mitre_limit` half widths, split into
  two columns overlapping by `overlap` mm otherwise.

Random: `random_width` (a share, each side) and `random_phase` of split stitches, seeded by
`seed` and the stroke's place in the design: the same options give the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.column_stitches import UNDERLAYS, ColumnStitching, column_needles
from fabrication.embroidery.columns import CORNER_ANGLE, MITRE_LIMIT, OVERLAP, stroke_columns
from fabrication.embroidery.needles import GRID, LONGEST_STITCH, NeedlePoints
from fabrication.embroidery.running import DENSE_TOLERANCE, STITCH_LENGTH, TOLERANCE
from fabrication.embroidery.sampling import dense_curve
from fabrication.embroidery.zigzag import PULL_COMPENSATION, SPACING, STITCH_WIDTH
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import Stroke

# 'auto' underlay: none below NARROW mm (a walk down the middle of so narrow a column
# crowds its needle points beyond the density limit, and it needs no support), up to
# CENTRE_ONLY mm a centre walk, up to EDGE_ONLY an edge walk, wider both edge walk and
# zigzag underlay.
NARROW, CENTRE_ONLY, EDGE_ONLY = 1.0, 2.0, 4.0


def parse_underlay(value) -> tuple[str, ...] | str:
    """'auto', or underlay kinds in sewing order from 'none', 'center', 'edge+zigzag', ...
    (True: center, False: none); `InputError` naming the bad part."""
    if value is None or value == "auto":
        return "auto"
    if isinstance(value, bool):
        return ("center",) if value else ()
    if isinstance(value, (tuple, list)):
        parts = list(value)
    else:
        text = str(value).strip().lower()
        if text == "auto":
            return "auto"
        parts = [] if text in ("none", "") else text.replace(",", "+").split("+")
    kinds = tuple(p.strip().replace("centre", "center").replace("contour", "edge") for p in parts)
    for kind in kinds:
        if kind not in UNDERLAYS:
            raise InputError(f"underlay {value!r}: {kind!r} is not one of {', '.join(UNDERLAYS)} "
                             "(join several with +, or none, or auto)")
    if len(set(kinds)) != len(kinds):
        raise InputError(f"underlay {value!r} names a kind twice")
    return kinds


# Declared ranges (the CLI's flags name them); --stitch-width, --spacing and --pull-comp are
# the zigzag's, the underlay stitch length the running stitch's.
WIDTH_SCALE = Range(0.1, 10.0, name="--width-scale")
MIN_WIDTH = Range(GRID, 12.0, unit="mm", name="--min-width")
MAX_WIDTH = Range(GRID, 12.0, unit="mm", name="--max-width")
PULL_PERCENT = Range(0.0, 1.0, unit="%", name="--pull-comp-percent", scale=100.0)
UNDERLAY_INSET = Range(0.0, 5.0, unit="mm", name="--underlay-inset")
ZIGZAG_INSET = Range(0.0, 5.0, unit="mm", name="--zigzag-underlay-inset")
UNDERLAY_SPACING = Range(0.5, 20.0, unit="mm", name="--underlay-spacing")
SHORT_DISTANCE = Range(0.0, 5.0, unit="mm", name="--short-stitch-distance")
SHORT_INSET = Range(0.0, 0.5, unit="%", name="--short-stitch-inset", scale=100.0)
MIN_GAP = Range(0.0, 2.0, unit="mm", name="satin minimum gap")
SPLIT_LENGTH = Range(1.0, LONGEST_STITCH, unit="mm", name="--split-length")
RANDOM_WIDTH = Range(0.0, 0.5, unit="%", name="--random-width", scale=100.0)
SEED = Range(0, 2**31 - 1, name="--seed", integer=True)


@dataclass(frozen=True, kw_only=True)
class SatinOptions:
    """width: constant column width mm, None = the drawn width; width_scale: factor on the
    drawn width; min_width / max_width: mm; spacing: peak to peak mm; pull_compensation:
    mm added to the width; pull_compensation_percent: share of the width added; underlay:
    'auto', 'none' or kinds joined by + ('center', 'edge', 'zigzag'); underlay_stitch_length,
    edge_inset, zigzag_inset (None: half the edge inset), underlay_spacing: mm;
    short_stitch_distance mm / short_stitch_inset (share of the width); min_gap mm (module
    doc of `column_stitches`); max_stitch_length: wider rows are split, mm; random_width:
    share each side; random_phase: random split points; seed; corner_angle degrees;
    mitre_limit: half widths; overlap mm; tolerance: the walks' chord tolerance mm."""

    width: float | None = ranged(None, STITCH_WIDTH)
    width_scale: float = ranged(1.0, WIDTH_SCALE)
    min_width: float = ranged(0.5, MIN_WIDTH)
    max_width: float = ranged(8.0, MAX_WIDTH)
    spacing: float = ranged(0.4, SPACING)
    pull_compensation: float = ranged(0.0, PULL_COMPENSATION)
    pull_compensation_percent: float = ranged(0.0, PULL_PERCENT)
    underlay: object = "auto"
    underlay_stitch_length: float = ranged(3.0, STITCH_LENGTH.named("underlay stitch length"))
    edge_inset: float = ranged(0.4, UNDERLAY_INSET)
    zigzag_inset: float | None = ranged(None, ZIGZAG_INSET)
    underlay_spacing: float = ranged(3.0, UNDERLAY_SPACING)
    short_stitch_distance: float = ranged(0.25, SHORT_DISTANCE)
    short_stitch_inset: float = ranged(0.15, SHORT_INSET)
    min_gap: float = ranged(0.35, MIN_GAP)
    max_stitch_length: float = ranged(7.0, SPLIT_LENGTH)
    random_width: float = ranged(0.0, RANDOM_WIDTH)
    random_phase: bool = False
    seed: int = ranged(0, SEED)
    corner_angle: float = ranged(45.0, CORNER_ANGLE)
    mitre_limit: float = ranged(2.0, MITRE_LIMIT)
    overlap: float = ranged(0.3, OVERLAP)
    tolerance: float = ranged(0.2, TOLERANCE)

    def __post_init__(self) -> None:
        check_ranges(self)
        if self.min_width > self.max_width:
            raise InputError(f"--min-width {self.min_width:g} mm is above --max-width {self.max_width:g} mm")
        if not isinstance(self.random_phase, bool):
            raise InputError(f"random phase {self.random_phase!r} must be true or false")
        object.__setattr__(self, "underlay", parse_underlay(self.underlay))

    def sewn_width(self, drawn: np.ndarray) -> np.ndarray:
        """Needle width mm of rows whose drawn width (mm, already scaled with the design) is
        `drawn`: the width option or drawn x scale within [min, max], then compensated."""
        base = np.full(np.shape(drawn), self.width) if self.width is not None else \
            np.clip(np.asarray(drawn, dtype=float) * self.width_scale, self.min_width, self.max_width)
        return base * (1.0 + self.pull_compensation_percent) + self.pull_compensation

    def reach(self, widest: float) -> float:
        """How far needle points stray from the curve (mm) for a drawn width up to `widest`."""
        return float(self.sewn_width(np.array([widest]))[0]) / 2.0

    def underlays_for(self, width: float) -> tuple[str, ...]:
        """The underlay kinds for a column about `width` mm wide."""
        if self.underlay != "auto":
            return self.underlay  # type: ignore[return-value]
        if width < NARROW:
            return ()
        if width <= CENTRE_ONLY:
            return ("center",)
        return ("edge",) if width <= EDGE_ONLY else ("edge", "zigzag")


def satin_stitch(stroke: Stroke, options: SatinOptions = SatinOptions(), *, default_width: float = 2.0,
                 seed: int = 0) -> NeedlePoints:
    """A satin column along `stroke` (mm); `default_width`: the drawn width (mm) when the
    stroke carries none; `seed`: mixed with the options' seed (the stroke's place)."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)
    profile = stroke.widths
    if profile is None:
        profile = np.array([[0.0, default_width], [1.0, default_width]])

    def half_at(s: np.ndarray) -> np.ndarray:
        drawn = np.interp(curve.t_at(s), profile[:, 0], profile[:, 1])
        return options.sewn_width(drawn) / 2.0

    half = half_at(curve.s)
    columns = stroke_columns(stroke, curve, half_at, options.spacing, corner_angle=options.corner_angle,
                             mitre_limit=options.mitre_limit, overlap=options.overlap)
    width = 2.0 * float(np.median(half))
    how = ColumnStitching(
        spacing=options.spacing, short_stitch_distance=options.short_stitch_distance,
        short_stitch_inset=options.short_stitch_inset, min_gap=options.min_gap,
        max_stitch=options.max_stitch_length, random_width=options.random_width, random_phase=options.random_phase,
        underlays=options.underlays_for(width), underlay_stitch_length=options.underlay_stitch_length,
        edge_inset=options.edge_inset,
        zigzag_inset=options.zigzag_inset if options.zigzag_inset is not None else options.edge_inset / 2.0,
        underlay_spacing=options.underlay_spacing, tolerance=options.tolerance)
    rng = np.random.default_rng([options.seed, seed]) if options.random_width or options.random_phase else None
    return column_needles(stroke, curve, columns, how, rng)
