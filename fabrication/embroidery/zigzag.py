"""Zigzag across the curve (paper Fig. 13 middle): needle points alternate side to side.

Centre points every spacing/2 along the curve (an even number of them), each pushed
perpendicular to the local direction by width/2 + pull_compensation/2, alternating sides.
The direction is the chord over +-reach around the point: the tangent on straight parts
and arcs, a fan round a bend.
On tight inner curves the inside points crowd: every other inner point is inset
(Ink/Stitch's short stitches; 30 % where points on the rail come closer than 0.35 mm,
deep enough that the inset holes stay 0.35 mm from their rail neighbours), the inside
reach is capped below the curve radius, and a rail point still closer than `min_gap` to
one of the last few on its rail is inset deeper, and left out only when that cannot clear
it (a point left out bares its side between its neighbours: a slit). Where needle points
still crowd past the density limit or re-enter a hole, they are relieved as a satin's are
(`fabrication.embroidery.crowding`). Zigs longer than `max_stitch` are split at staggered
points. Underlay (sewn first, there and back so the zigzag starts where the stroke does):
'center' a walk along the curve (back between the holes of the way out), 'edge' a walk
along each rail inset from the edge, 'zigzag' a sparse zigzag inset from the edges, out
and back in opposite phase; by default a centre walk once the zigzag is wider than
`underlay_min_width`, none on a stroke no longer than one underlay stitch.

A stroke with kinks (a turn sharper than `corner_angle` within KINK mm: the wave drawing's
fold, a polyline's corners) is sewn by satin's column engine at the zigzag's width
(`fabrication.embroidery.columns`): corners mitred, or split into two columns that overlap
by `overlap` mm where the mitre would reach past `mitre_limit` half widths, so a corner is
covered once: no spur of loose stitches, no pile-up, no slit.
"""

from __future__ import annotations

import heapq
import itertools
from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.column_stitches import ColumnStitching, column_needles, split_body
from fabrication.embroidery.columns import CORNER_ANGLE, MITRE_LIMIT, OVERLAP, find_corners, stroke_columns
from fabrication.embroidery.crowding import relieve_crowding, straight_density
from fabrication.embroidery.needles import BODY, GRID, SNAP_ALLOWANCE, UNDERLAY, NeedlePoints
from fabrication.embroidery.running import (DENSE_TOLERANCE, STITCH_LENGTH, TOLERANCE, RunningOptions,
                                            running_stitch)
from fabrication.embroidery.quality import DENSITY_LIMIT, stroke_sides
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

# The inside reach stays below this fraction of the curve radius, so inner points never
# pass the centre of curvature (they would sew loops and run backwards).
MAX_INNER_REACH = 0.75
# A turn sharper than the corner angle within this many mm either side is a kink.
KINK = 0.25
# A crowded point is inset towards the curve by at most this share of its reach.
MAX_INSET = 0.5
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


def _inset_crowded(points: np.ndarray, centre: np.ndarray, min_gap: float, inner: np.ndarray, step: float, *,
                   window: int = 6) -> np.ndarray:
    """Mask of points to keep so that no `inner` point comes within `min_gap` of the last
    `window` kept points on its rail (rails alternate: even and odd indices; on a very
    tight curve the inner rail winds round a small circle, so not only the previous point
    can be near). A crowded point is first inset towards its centre point `centre` (N, 2),
    `step` (a share of its reach) at a time, up to MAX_INSET of the reach (in place, in
    `points`): a point left out would leave its side bare between its neighbours, a slit;
    only one that cannot be cleared so is left out. Points outside curves or on straight
    parts keep the requested spacing. Only crowded points and the ones after a changed
    point are visited one by one."""
    n = len(points)
    keep = np.ones(n, dtype=bool)
    nearest = np.full(n, np.inf)
    for lag in range(2, 2 * window + 1, 2):
        d = np.linalg.norm(points[lag:] - points[:-lag], axis=1)
        nearest[lag:] = np.minimum(nearest[lag:], d)
    work = np.flatnonzero((nearest < min_gap) & inner).tolist()
    heapq.heapify(work)
    queued = set(work)
    steps = np.arange(1, int(MAX_INSET / step + 1e-9) + 1) * step if step > 0 else np.zeros(0)
    while work:
        i = heapq.heappop(work)
        if i == n - 1 or not inner[i]:
            continue  # the end point anchors the lock
        kept = list(itertools.islice((k for k in range(i - 2, -1, -2) if keep[k]), window))
        if not kept or np.min(np.hypot(*(points[kept] - points[i]).T)) >= min_gap:
            continue
        rail = points[i].copy()
        for share in steps:
            q = rail + (centre[i] - rail) * share
            if np.min(np.hypot(*(points[kept] - q).T)) >= min_gap:
                points[i] = q
                break
        else:
            keep[i] = False
        for nxt in range(i + 2, min(n, i + 2 * window + 1), 2):
            if inner[nxt] and nxt not in queued:
                queued.add(nxt)
                heapq.heappush(work, nxt)
    return keep


def zigzag_stitch(stroke: Stroke, options: ZigzagOptions = ZigzagOptions()) -> NeedlePoints:
    """Zigzag along `stroke` (mm), preceded by a there-and-back centre walk when wide; a
    stroke with kinks is sewn as satin's columns are, corners mitred or split (module doc)."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)
    # A kink (a turn sharper than the corner angle within KINK mm, not a tight arc, which
    # the zigzag's own rows follow) makes a stroke one of columns with corners.
    if find_corners(stroke, curve, np.full(len(curve.s), KINK), options.corner_angle):
        return _cornered(stroke, curve, options)
    length = curve.length
    steps = max(1, int(round(2.0 * length / options.spacing)))
    if steps % 2 == 0:
        steps += 1  # an even number of points: the zigzag ends on the other rail
    s = np.linspace(0.0, length, steps + 1)
    t = curve.t_at(s)
    centre = stroke.points_at(t)
    # Direction of the chord over +-reach around each point: the tangent on straight parts
    # and arcs, and a fan that turns smoothly round a sharp corner instead of jumping
    # (which would leave a wedge outside the corner and cross over inside it).
    # The window stays symmetric near the ends, where it shrinks to the exact tangent.
    w = np.minimum(options.reach, np.minimum(s, length - s))
    chord = stroke.points_at(curve.t_at(s + w)) - stroke.points_at(curve.t_at(s - w))
    norm = np.linalg.norm(chord, axis=1, keepdims=True)
    tangent = np.where(norm > 1e-6, chord / np.maximum(norm, 1e-12), stroke.tangents_at(t))
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    theta = np.unwrap(np.arctan2(tangent[:, 1], tangent[:, 0]))
    kappa = np.gradient(theta, s) if len(s) > 2 else np.zeros(len(s))
    side = np.where(np.arange(len(s)) % 2 == 0, 1.0, -1.0)
    reach = np.full(len(s), options.reach)
    inner = side * kappa > 0
    radius = 1.0 / np.maximum(np.abs(kappa), 1e-12)
    reach[inner] = np.minimum(reach[inner], MAX_INNER_REACH * radius[inner])
    # Same-rail spacing on the inside shrinks by (1 - reach / radius).
    rail_gap = 2.0 * (length / steps) * (1.0 - reach * np.abs(kappa))
    short = inner & (rail_gap < options.short_stitch_distance) & ((np.arange(len(s)) // 2) % 2 == 1)
    reach[short] *= 1.0 - options.short_stitch_inset
    points = centre + normal * (side * reach)[:, None]
    # Inner points of a real curve (radius under 50 mm) may be inset or dropped when crowded.
    keep = _inset_crowded(points, centre, options.min_gap, inner & (np.abs(kappa) > 0.02), options.short_stitch_inset)
    points, t, centre = points[keep], t[keep], centre[keep]
    zig = NeedlePoints.of(points, t, BODY)
    room = (centre - points) * MAX_INSET
    # An underlay goes there and back and ends on the start; along a stroke no longer than
    # one underlay stitch it would re-enter its first hole two stitches later (a knot on a
    # short stroke), and so short a column does not pucker without it.
    if options.has_underlay and length > options.underlay_stitch_length:
        under = _underlay(stroke, curve, options)
        zig = NeedlePoints.concat([under, zig])
        room = np.concatenate([np.zeros((len(under), 2)), room])
    # Where the needle points still crowd past the density limit or re-enter a hole, they
    # are relieved (`crowding`: underlay points left out, zigzag points inset); where the
    # spacing asked is itself too dense, it is warned about, not hidden.
    if straight_density(options.spacing, 2.0 * options.reach) <= DENSITY_LIMIT:
        points, keep = relieve_crowding(zig.points, zig.roles, room,
                                        lambda rows, at: stroke_sides(stroke, at, zig.t[rows]),
                                        max_gap=2.0 * options.underlay_stitch_length, max_top_gap=2.0 * options.spacing,
                                        spacing=options.spacing)
        zig = NeedlePoints(points, zig.t, zig.roles).take(keep)
    return split_body(zig, options.max_stitch - 2 * SNAP_ALLOWANCE)


def _cornered(stroke: Stroke, curve, options: ZigzagOptions) -> NeedlePoints:
    """Zigzag along a stroke with corners: the constant-width columns of satin's engine,
    mitred or split at the corners (`fabrication.embroidery.columns`)."""
    def half_at(s: np.ndarray) -> np.ndarray:
        return np.full(len(s), options.reach)

    columns = stroke_columns(stroke, curve, half_at, options.spacing, corner_angle=options.corner_angle,
                             mitre_limit=options.mitre_limit, overlap=options.overlap)
    kind = options.underlay_kind if curve.length > options.underlay_stitch_length else "none"
    # The zigzag's underlay inset counts from the drawn edge, the columns' from the rail.
    inset = options.reach - max(0.0, options.width / 2.0 - options.underlay_inset)
    how = ColumnStitching(
        spacing=options.spacing, short_stitch_distance=options.short_stitch_distance,
        # the zigzag's inset is a share of its reach, the columns' of the row's width (twice it)
        short_stitch_inset=options.short_stitch_inset / 2.0, min_gap=options.min_gap, max_stitch=options.max_stitch,
        underlays=() if kind == "none" else (kind,), underlay_stitch_length=options.underlay_stitch_length,
        edge_inset=inset, zigzag_inset=inset, underlay_spacing=options.underlay_spacing, tolerance=options.tolerance)
    return column_needles(stroke, curve, columns, how)


def _offset(stroke: Stroke, t: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Points at parameters t pushed along the left normal by `offset` (mm, signed)."""
    tangent = stroke.tangents_at(t)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    return stroke.points_at(t) + normal * np.asarray(offset, dtype=float).reshape(-1, 1)


def _underlay(stroke: Stroke, curve, options: ZigzagOptions) -> NeedlePoints:
    """Underlay needle points, there and back: they end on the stroke's start."""
    walk = running_stitch(stroke, RunningOptions(stitch_length=options.underlay_stitch_length,
                                                 tolerance=options.tolerance), curve=curve)
    kind = options.underlay_kind
    inset = max(0.0, options.width / 2.0 - options.underlay_inset)
    if kind == "center" or inset < 0.2:
        # The walk back pierces halfway between the holes of the walk out, ending on the start.
        back_t = np.concatenate([0.5 * (walk.t[:-1] + walk.t[1:])[::-1], [walk.t[0]]])
        return NeedlePoints.of(np.concatenate([walk.points, stroke.points_at(back_t)]),
                               np.concatenate([walk.t, back_t]), UNDERLAY)
    # The inner side of a tight curve cannot reach past its centre of curvature.
    kappa = np.interp(walk.t, curve.t, curve.curvature)
    room = MAX_INNER_REACH / np.maximum(np.abs(kappa), 1e-12)
    left = np.minimum(inset, np.where(kappa > 0, room, np.inf))
    right = np.minimum(inset, np.where(kappa < 0, room, np.inf))
    if kind == "edge":
        out = _offset(stroke, walk.t, left)
        back = _offset(stroke, walk.t[::-1], -right[::-1])
        pts = np.concatenate([walk.points[:1], out, back, walk.points[:1]])
        t = np.concatenate([walk.t[:1], walk.t, walk.t[::-1], walk.t[:1]])
        return NeedlePoints.of(pts, t, UNDERLAY)
    # Zigzag underlay: a sparse zigzag out, the opposite phase back.
    steps = max(2, int(round(2.0 * curve.length / options.underlay_spacing)))
    s = np.linspace(0.0, curve.length, steps + 1)
    t = curve.t_at(s)
    k = np.interp(t, curve.t, curve.curvature)
    room = MAX_INNER_REACH / np.maximum(np.abs(k), 1e-12)
    side = np.where(np.arange(len(s)) % 2 == 0, 1.0, -1.0)
    reach = np.minimum(inset, np.where(side * k > 0, room, np.inf))
    out = _offset(stroke, t, side * reach)
    back = _offset(stroke, t[::-1], (-side * np.minimum(inset, np.where(-side * k > 0, room, np.inf)))[::-1])
    pts = np.concatenate([walk.points[:1], out, back, walk.points[:1]])
    tt = np.concatenate([walk.t[:1], t, t[::-1], walk.t[:1]])
    return NeedlePoints.of(pts, tt, UNDERLAY)
