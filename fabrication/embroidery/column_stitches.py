"""Needle points of columns (`fabrication.embroidery.columns`): the top stitches across each
column and the underlays beneath it, for the satin and zigzag styles.

Top stitches go from rail to rail, one row after the other, alternating sides. Where the
rows crowd on a rail (inside a bend), every other crowded point ends short of it by
`short_stitch_inset` of the row's width (Ink/Stitch's short stitches: 15 % where points on a
rail come closer than 0.25 mm); a point still within `min_gap` of one of the last two on its
side (a needle entering a hole it made a moment before) is inset deeper, step by step, up
to half the row's width, except a column's first and last point on each side. Stitches longer than `max_stitch` are split at staggered points
(or at a random phase). `random_width` varies each row's reach on either side (seeded).

Underlays (sewn first, each out and back so the top starts near where the column does, none
on a column under 2 mm):
'center' a walk along the centre line (back between the holes of the way out), 'edge' a
walk along each rail inset from the edge (Ink/Stitch's contour underlay), 'zigzag' a sparse
zigzag inset from the edges, out and back in opposite phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.columns import Column, Rows
from fabrication.embroidery.crowding import relieve_crowding, straight_density
from fabrication.embroidery.needles import BODY, SNAP_ALLOWANCE, UNDERLAY, NeedlePoints
from fabrication.embroidery.quality import DENSITY_LIMIT, stroke_sides
from fabrication.embroidery.running import RunningOptions, running_stitch
from fabrication.embroidery.sampling import DenseCurve
from vectorize.stroke import Stroke

UNDERLAYS = ("center", "edge", "zigzag")
SHORT_COLUMN = 2.0  # mm
# A crowded point is inset deeper, one short-stitch step at a time, up to this share of its
# row's width.
MAX_INSET = 0.5
# A cut end may run on under the column sewn over it by up to this much more (mm).
RUN_UNDER = 0.5


@dataclass(frozen=True, kw_only=True)
class ColumnStitching:
    """How columns are sewn (the satin and zigzag options, in one form): spacing, peak to
    peak mm; short_stitch_distance mm / short_stitch_inset (share of the row's width);
    min_gap: the closest a needle may come to the last two on its side, mm; max_stitch mm;
    random_width: each row's reach either side varies by up to this share; random_phase:
    split points at a random phase instead of staggered; underlays: kinds in sewing order;
    underlay_stitch_length mm; edge_inset / zigzag_inset mm inside the edges; underlay_spacing
    mm peak to peak; tolerance: the walks' chord tolerance mm."""

    spacing: float
    short_stitch_distance: float
    short_stitch_inset: float
    min_gap: float
    max_stitch: float
    random_width: float = 0.0
    random_phase: bool = False
    underlays: tuple[str, ...] = ()
    underlay_stitch_length: float = 3.0
    edge_inset: float = 0.4
    zigzag_inset: float = 0.2
    underlay_spacing: float = 3.0
    tolerance: float = 0.2


def column_needles(stroke: Stroke, curve: DenseCurve, columns: list[Column], how: ColumnStitching,
                   rng: np.random.Generator | None = None) -> NeedlePoints:
    """Every column's underlays then top stitches, in order along the stroke, with the
    crowding relieved (`crowding`). A column cut away entirely (its ground lies under the
    next one) is crossed by a walk on its centre."""
    spans = [_span(c) if len(c.rows) >= 2 else (c.start, c.end) for c in columns]
    # One running stitch along the whole stroke, meeting every column's ends: the walks.
    walk = running_stitch(stroke, RunningOptions(stitch_length=how.underlay_stitch_length, tolerance=how.tolerance),
                          curve=curve, breaks=np.array(spans).ravel())
    walk_s = np.interp(walk.t, curve.t, curve.s)
    parts, inward = [], []
    for column, (lo, hi) in zip(columns, spans):
        inside = walk_s[(walk_s >= lo - 1e-9) & (walk_s <= hi + 1e-9)]
        s = inside if len(inside) >= 2 else np.array([lo, hi])
        if len(column.rows) < 2:
            t = curve.t_at(s)
            parts.append(NeedlePoints.of(stroke.points_at(t), t, UNDERLAY))
            inward.append(np.zeros((len(s), 2)))
            continue
        # A column shorter than SHORT_COLUMN (a corner's jog, a short stroke) has no room
        # for an underlay: its walks would only pile needle points on its start.
        for kind in how.underlays if hi - lo >= SHORT_COLUMN else ():
            under = _UNDERLAY[kind](column, s, how)
            parts.append(under)
            inward.append(np.zeros((len(under), 2)))
        top, room = top_points(column.rows, how, rng)
        parts.append(top)
        inward.append(room)
    merged = NeedlePoints.concat(parts)
    if not len(merged):
        return merged
    widths = np.concatenate([c.rows.left + c.rows.right for c in columns if len(c.rows)] or [np.zeros(1)])
    # Where the spacing asked is itself too dense, it is warned about, not hidden.
    if straight_density(how.spacing, float(np.median(widths))) <= DENSITY_LIMIT:
        points, keep = relieve_crowding(merged.points, merged.roles, np.concatenate(inward),
                                        lambda rows, at: stroke_sides(stroke, at, merged.t[rows]),
                                        max_gap=2.0 * how.underlay_stitch_length, max_top_gap=2.0 * how.spacing,
                                        spacing=how.spacing)
        merged = NeedlePoints(points, merged.t, merged.roles).take(keep)
    return split_body(merged, how.max_stitch - 2 * SNAP_ALLOWANCE, rng if how.random_phase else None)


def split_body(needles: NeedlePoints, max_length: float, rng: np.random.Generator | None = None) -> NeedlePoints:
    """`needles` with each run of top stitches split where longer than `max_length` mm."""
    body = np.concatenate([[False], needles.roles == BODY, [False]])
    edges = np.flatnonzero(np.diff(body.astype(int)))
    pieces, last = [], 0
    for a, b in zip(edges[::2], edges[1::2]):
        pieces.append(needles.take(np.arange(last, a)))
        points, t = split_long(needles.points[a:b], needles.t[a:b], max_length, rng)
        pieces.append(NeedlePoints.of(points, t, BODY))
        last = b
    pieces.append(needles.take(np.arange(last, len(needles))))
    return NeedlePoints.concat(pieces)


def top_points(rows: Rows, how: ColumnStitching,
               rng: np.random.Generator | None = None) -> tuple[NeedlePoints, np.ndarray]:
    """Rail to rail across `rows`, alternating sides, with short stitches (module doc), not
    yet split; and how far (N, 2) mm each point may still move: inset towards its row's
    centre (to MAX_INSET of its width), or on a cut end, on under the column over it."""
    n = len(rows)
    side = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    width = rows.left + rows.right
    reach = np.where(side > 0, rows.left, rows.right)
    if how.random_width > 0 and rng is not None:
        reach = reach * (1.0 + rng.uniform(-how.random_width, how.random_width, n))
    # Signed offset from the centre along the normal, and the most a point may be inset.
    offset = side * reach
    points = rows.centre + rows.normal * offset[:, None]
    step = how.short_stitch_inset * width
    # Short stitches: on each side, every other point of a run closer than the distance to
    # the one before it on that side.
    gap = np.full(n, np.inf)
    gap[2:] = np.linalg.norm(points[2:] - points[:-2], axis=1)
    crowded = gap < how.short_stitch_distance
    run = np.zeros(n, dtype=int)
    for parity in (0, 1):
        c = crowded[parity::2]
        # position within each run of crowded points on this side (1, 2, 3, ...)
        count = np.cumsum(c)
        reset = np.maximum.accumulate(np.where(~c, count, 0))
        run[parity::2] = count - reset
    depth = np.where(run % 2 == 1, step, 0.0)
    offset = offset - side * depth
    points = rows.centre + rows.normal * offset[:, None]
    points = _keep_holes_apart(points, rows, side, offset, step, width, how.min_gap)
    now = np.einsum("ij,ij->i", points - rows.centre, rows.normal)
    deepest = side * np.maximum(reach - MAX_INSET * width, 0.0)
    room = np.where(side * (now - deepest) > 0, deepest - now, 0.0)
    # A point on a cut end (under the column sewn on top of this one) may instead run on
    # deeper under it: away from that column's edge, where its own needle points crowd.
    full = np.where(side > 0, rows.reach[:, 0], rows.reach[:, 1])
    cut = full > reach + 1e-6
    room = np.where(cut, side * np.minimum(full - side * now, RUN_UNDER), room)
    return NeedlePoints.of(points, rows.t, BODY), rows.normal * room[:, None]


def _keep_holes_apart(points, rows: Rows, side, offset, step, width, min_gap) -> np.ndarray:
    """Inset each point that comes within `min_gap` of one of the last two on its side,
    one `step` at a time, up to MAX_INSET of its row's width (module doc). Only crowded
    points are visited, in order."""
    n = len(points)
    if n < 3:
        return points
    near = np.zeros(n, dtype=bool)
    for lag in (2, 4):
        near[lag:] |= np.linalg.norm(points[lag:] - points[:-lag], axis=1) < min_gap
    todo = np.flatnonzero(near)
    if not len(todo):
        return points
    # Python floats: the loop touches single points (the same operations as on numpy's
    # scalars: np.hypot of the differences, centre + normal x offset per coordinate).
    out = points.tolist()
    centre, normal = rows.centre.tolist(), rows.normal.tolist()
    offset, side, step, width = (np.asarray(v, dtype=float).tolist() for v in (offset, side, step, width))
    hypot = np.hypot
    for i in todo.tolist():
        # A column's first and last point on each side keep their reach: its ends stay
        # square (the last on the inside of a bend went as deep as the steps before it, and
        # bared the column's end there: a slit).
        if i < 2 or i >= n - 2:
            continue
        (ax, ay), (bx, by) = out[i - 2], out[i - 4] if i >= 4 else out[i - 2]
        here, stride, limit = offset[i], step[i], MAX_INSET * width[i]
        inset = 0.0
        px, py = out[i]
        while min(hypot(px - ax, py - ay), hypot(px - bx, py - by)) < min_gap and inset + stride <= limit + 1e-9 \
                and stride > 0:
            inset += stride
            k = here - side[i] * inset
            px, py = centre[i][0] + normal[i][0] * k, centre[i][1] + normal[i][1] * k
        out[i] = [px, py]
    return np.array(out, dtype=float)


def split_long(points: np.ndarray, t: np.ndarray, max_length: float,
               rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Split stitches longer than `max_length` into real stitches: at staggered fractions so
    that the split points of neighbouring stitches do not line up into a ridge, or at a
    random phase (`rng`)."""
    seg = np.diff(points, axis=0)
    length = np.linalg.norm(seg, axis=1)
    # Staggers up to 1/3 of a piece make the longest piece (1 + 1/3) / n of the stitch.
    n = np.maximum(1, np.ceil(length * (4.0 / 3.0) / max_length)).astype(int)
    n[length <= max_length] = 1
    if n.max() == 1:
        return points, t
    if rng is None:
        stagger = np.array([0.0, 1.0 / 3.0, -1.0 / 3.0])[np.arange(len(n)) % 3]
    else:
        stagger = rng.uniform(-1.0 / 3.0, 1.0 / 3.0, len(n))
    extra = n - 1
    owner = np.repeat(np.arange(len(n)), extra)
    k = np.arange(extra.sum()) - np.repeat(np.cumsum(extra) - extra, extra) + 1
    frac = (k - stagger[owner]) / n[owner]
    new_pts = points[owner] + seg[owner] * frac[:, None]
    new_t = t[owner] + (t[owner + 1] - t[owner]) * frac
    # Insert after the start of each owning stitch, keeping the order along each stitch.
    order = np.argsort(np.concatenate([np.arange(len(points)) * 1.0, owner + frac * 0.999]), kind="stable")
    return np.concatenate([points, new_pts])[order], np.concatenate([t, new_t])[order]


# -- underlays ---------------------------------------------------------------------------------

def _offsets(column: Column, s: np.ndarray, inset: float, side: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points at arc lengths `s` (within the column) on `side` (+1 left, -1 right; 0 the
    centre), `inset` mm inside the rails (never past the centre), and their parameters."""
    rows = column.rows
    order = np.argsort(rows.s, kind="stable")
    rs = rows.s[order]
    centre = np.column_stack([np.interp(s, rs, rows.centre[order, 0]), np.interp(s, rs, rows.centre[order, 1])])
    normal = np.column_stack([np.interp(s, rs, rows.normal[order, 0]), np.interp(s, rs, rows.normal[order, 1])])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    reach = np.where(side > 0, np.interp(s, rs, rows.left[order]), np.interp(s, rs, rows.right[order]))
    reach = np.maximum(reach - inset, 0.0) * np.abs(side)
    return centre + normal * (side * reach)[:, None], np.interp(s, rs, rows.t[order])


def _span(column: Column) -> tuple[float, float]:
    """The arc lengths the column's kept rows cover (cut-back rows shorten it)."""
    return float(column.rows.s.min()), float(column.rows.s.max())


def _centre_underlay(column: Column, s: np.ndarray, how: ColumnStitching) -> NeedlePoints:
    """Centre walk out (needle points at arc lengths `s`), and back between the holes of the
    way out, ending on the start."""
    back = 0.5 * (s[:-1] + s[1:])[::-1]  # ends between the first two holes, not in the first
    everywhere = np.concatenate([s, back])
    points, t = _offsets(column, everywhere, 0.0, np.zeros(len(everywhere)))
    return NeedlePoints.of(points, t, UNDERLAY)


def _edge_underlay(column: Column, s: np.ndarray, how: ColumnStitching) -> NeedlePoints:
    """Along the left rail, `edge_inset` inside it, then back along the right one (needle
    points at arc lengths `s`)."""
    out, t_out = _offsets(column, s, how.edge_inset, np.ones(len(s)))
    back, t_back = _offsets(column, s[::-1], how.edge_inset, -np.ones(len(s)))
    return NeedlePoints.of(np.concatenate([out, back]), np.concatenate([t_out, t_back]), UNDERLAY)


def _zigzag_underlay(column: Column, s: np.ndarray, how: ColumnStitching) -> NeedlePoints:
    """A sparse zigzag `zigzag_inset` inside the edges out, the opposite phase back (over
    the arc lengths `s` span)."""
    lo, hi = float(s[0]), float(s[-1])
    steps = max(2, int(round(2.0 * (hi - lo) / how.underlay_spacing)))
    s = np.linspace(lo, hi, steps + 1)
    side = np.where(np.arange(len(s)) % 2 == 0, 1.0, -1.0)
    out, t_out = _offsets(column, s, how.zigzag_inset, side)
    back, t_back = _offsets(column, s[::-1], how.zigzag_inset, -side[::-1])
    return NeedlePoints.of(np.concatenate([out, back]), np.concatenate([t_out, t_back]), UNDERLAY)


_UNDERLAY = {"center": _centre_underlay, "edge": _edge_underlay, "zigzag": _zigzag_underlay}
