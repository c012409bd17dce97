"""Curve fitting (paper 3.4): filter uncertain points, split at sharp features, fit cubic
B-splines with `scipy.interpolate.splprep`, and convert them to Bézier segments."""

from __future__ import annotations

import bisect

import numpy as np
from scipy.interpolate import splev, splprep
from scipy.spatial import cKDTree

from vectorize.fit.ink_guard import MARGIN, STEP, InkGuard, curve_excess, keep_in_ink
from vectorize.fit.retraces import (
    Twin,
    mirror_flags,
    mirror_keep,
    rolled,
    share_pieces,
    twin_piece,
    valid_twins,
)
from vectorize.fit.tips import corner_tip, pruned_cusps, with_fork_tips
from vectorize.fit.traced import POINT, TracedPoints, point_records
from vectorize.stroke import Stroke, arc_lengths, edge_lengths


# The first fit of a piece takes about one traced point per THIN stroke widths of arc
# length (`thinned`), and every point within DENSE widths of an uncertain stretch.
THIN = 0.3
# ... and at most THIN_MAX px: a thick line's tight bend needs its points as much as a thin
# line's (on a 2.4 px grid the 8 px filled-outline figure eight came 1 px off at its bend).
THIN_MAX = 1.5
# Only pieces of more points than this are thinned: FITPACK's time is in the long ones.
THIN_FROM = 2000
DENSE = 3.0
# A joint that moves a piece this many stroke widths farther from one of its points than its fit
# left it (within 0.43 w of all of them as fitted, at the 222 corner pieces of three thin lines)
# dragged it off its line (`_refit_dragged`).
DRAGGED = 0.5


def _distinct(points: np.ndarray, min_step: float) -> np.ndarray:
    """Indices of the points to keep when those closer than `min_step` to the previous kept
    one are dropped (splprep needs distinct points); the last point is always kept."""
    n = len(points)
    if n < 2:
        return np.arange(n)
    steps = edge_lengths(points)
    keep = np.ones(n, dtype=bool)
    # A point is measured from the last kept one, which is its predecessor unless that one
    # was dropped: only the runs that start with a short step need walking point by point.
    done = 0
    for i in (np.flatnonzero(steps < min_step) + 1).tolist():
        if i <= done:
            continue
        last = i - 1
        while i < n and np.linalg.norm(points[i] - points[last]) < min_step:
            keep[i] = False
            i += 1
        done = i
    kept = np.flatnonzero(keep)
    if kept[-1] != n - 1 and np.linalg.norm(points[-1] - points[kept[-1]]) > 1e-9:
        kept[-1] = n - 1
    return kept


def bspline_to_bezier(tck, u_start: float, u_end: float) -> np.ndarray:
    """Bézier control points (K, 4, 2) of a parametric cubic spline between two parameters.

    Each knot span of a cubic spline is one cubic polynomial, so its Bézier form follows
    exactly from the end points and end derivatives (Hermite to Bézier); this works for
    periodic splines as well as open ones.
    """
    knots = np.unique(tck[0])
    breaks = np.unique(np.concatenate([[u_start, u_end], knots[(knots > u_start) & (knots < u_end)]]))
    a, b = breaks[:-1], breaks[1:]
    # Evaluate just inside each span so the derivative belongs to that span's polynomial.
    pa = np.array(splev(a, tck)).T
    pb = np.array(splev(b, tck)).T
    da = np.array(splev(a, tck, der=1)).T
    db = np.array(splev(b, tck, der=1)).T
    h = (b - a)[:, None] / 3.0
    return np.stack([pa, pa + h * da, pb - h * db, pb], axis=1)


def thinned(points: np.ndarray, spacing: float, dense: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The points of an (N, 2) ordered line to fit, and how many of its points each stands for.

    Returns (indices (M,) ascending, counts (M,) summing to N). Kept: the first and the last
    point, every point where `dense` ((N,) bool) says so, and where the line crosses a line
    of a `spacing` px grid, the point of the two beside it on the grid line's far side (about
    1.3 points per `spacing` px). The choice hangs on the points alone, not on where the line
    starts or which way it runs: the two passes of a retrace, fitted apart on the same
    centre-line points, get the same points and lie on each other instead of weaving across.
    Each point stands for the points halfway to its kept neighbours. spacing 0: every point.
    """
    n = len(points)
    if n < 3 or spacing <= 0.0:
        return np.arange(n), np.ones(n)
    cells = np.floor(points / spacing)
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    if dense is not None:
        keep |= dense
    for axis in (0, 1):
        crossed = np.flatnonzero(cells[1:, axis] != cells[:-1, axis])
        far = points[crossed + 1, axis] > points[crossed, axis]
        keep[np.where(far, crossed + 1, crossed)] = True
    kept = np.flatnonzero(keep)
    # point i stands for [i - 1/2, i + 1/2]: the same counts either way along the line
    bounds = np.concatenate([[-0.5], (kept[:-1] + kept[1:]) / 2.0, [n - 0.5]])
    return kept, np.diff(bounds)


def along_distance(arc: np.ndarray, marked: np.ndarray) -> np.ndarray:
    """(N,) px along the line from each point to the nearest marked one, either side
    (inf when none is); arc: (N,) ascending arc lengths, marked: (N,) bool."""
    at = arc[marked]
    if not at.size:
        return np.full(len(arc), np.inf)
    # one pass, not one per marked point: TSP art has thousands of corners
    k = np.searchsorted(at, arc)
    after = np.abs(at[np.minimum(k, at.size - 1)] - arc)
    before = np.abs(arc - at[np.maximum(k - 1, 0)])
    return np.minimum(before, after)


def fit_piece(points: np.ndarray, *, closed: bool, sigma: float, anchor: bool = True,
              spacing: float = 0.0, dense: np.ndarray | None = None, held: np.ndarray | None = None) -> np.ndarray:
    """Fit one piece: (N, 2) ordered points -> Bézier control points (K, 4, 2).

    sigma: expected noise of the points in px; the smoothing allows that much residual.
    anchor: make an open piece start and end exactly on its first and last points.
    spacing, dense: fit only the points `thinned` keeps (spacing 0: every point), each
    weighing as much as the points it stands for: about the same sum is minimised.
    held: (N,) how many points each point weighs besides (`TracedPoints.held`; None: one
    each); the smoothing's allowance stays that of the points themselves.
    """
    kept, count = thinned(points, spacing, dense)
    points = points[kept]
    distinct = _distinct(points, 1e-3)
    points, count = points[distinct], count[distinct]
    weigh = np.ones(len(points)) if held is None else np.asarray(held, dtype=float)[kept][distinct]
    if closed and len(points) > 3 and np.linalg.norm(points[0] - points[-1]) < 1e-6:
        points, count, weigh = points[:-1], count[:-1], weigh[:-1]
    if len(points) < 4 or (closed and len(points) < 6):
        line = points if len(points) >= 2 else np.vstack([points, points + 1e-3])
        if closed:
            line = np.vstack([line, line[:1]])
        return Stroke.from_polyline(line).control
    if closed:
        points, count = np.vstack([points, points[:1]]), np.append(count, count[0])
        weigh = np.append(weigh, weigh[0])
    u = arc_lengths(points)
    u /= u[-1]
    # FITPACK minimises sum((w * residual)^2) within s: weights sqrt(count) and s over all the
    # points stood for ask of the thinned points what the full fit asks of every point.
    smoothing = float(count.sum()) * sigma * sigma
    weight = np.sqrt(count * weigh) if (count * weigh != 1).any() else None
    try:
        tck, _ = splprep([points[:, 0], points[:, 1]], w=weight, u=u, k=3, s=smoothing, per=1 if closed else 0,
                         quiet=2)
    except (ValueError, TypeError):
        return Stroke.from_polyline(points).control
    control = bspline_to_bezier(tck, 0.0, 1.0)
    if not closed and anchor:
        # Anchor the ends on the data: strokes must start and end where the ink does.
        control[0, 1] += points[0] - control[0, 0]
        control[0, 0] = points[0]
        control[-1, 2] += points[-1] - control[-1, 3]
        control[-1, 3] = points[-1]
    if closed:
        control[-1, 3] = control[0, 0]
    return control


def _turn(xy: np.ndarray, arc: np.ndarray, reach: float, closed: bool) -> np.ndarray:
    """Turning angle (rad) at each point between the chords to the points `reach` before and after."""
    total = arc[-1]
    before = arc - reach
    after = arc + reach
    if closed:
        before, after = np.mod(before, total), np.mod(after, total)
    p0 = np.column_stack([np.interp(before, arc, xy[:, 0]), np.interp(before, arc, xy[:, 1])])
    p2 = np.column_stack([np.interp(after, arc, xy[:, 0]), np.interp(after, arc, xy[:, 1])])
    u, v = xy - p0, p2 - xy
    norm = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
    cos = np.where(norm > 1e-12, (u * v).sum(1) / np.maximum(norm, 1e-12), 1.0)
    angle = np.arccos(np.clip(cos, -1.0, 1.0))
    if not closed:
        angle[(arc < reach) | (arc > total - reach)] = 0.0
    return angle


def sharp_corners(xy: np.ndarray, stroke_width: float, *, closed: bool) -> np.ndarray:
    """Indices of sharp corners: turns over 40 degrees within 1.5 stroke widths, most of it
    within half a width (a tight smooth bend spreads its turn out; a corner does not)."""
    if len(xy) < 5:
        return np.zeros(0, dtype=int)
    arc = arc_lengths(xy)
    return _sharp_corners(xy, arc, _turn(xy, arc, 1.5 * stroke_width, closed), stroke_width, closed)


def _sharp_corners(xy: np.ndarray, arc: np.ndarray, wide: np.ndarray, stroke_width: float,
                   closed: bool) -> np.ndarray:
    """`sharp_corners` of a line of 5 points or more, given its arc lengths and its turn over
    1.5 widths (`_turn`), which `fit_stroke` reads again for `tips.pruned_cusps`."""
    narrow = _turn(xy, arc, 0.5 * stroke_width, closed)
    candidate = (wide > np.radians(40.0)) & (narrow > 0.6 * wide)
    corners: list[int] = []
    taken: list[float] = []  # arc lengths of the corners kept so far, sorted
    for i in np.flatnonzero(candidate)[np.argsort(-wide[candidate], kind="stable")]:
        # the nearest kept corners on either side (TSP art has thousands of corners: a scan of
        # all of them per candidate was most of its fitting time)
        k = bisect.bisect_left(taken, arc[i])
        if all(abs(arc[i] - taken[j]) > 2.0 * stroke_width for j in (k - 1, k) if 0 <= j < len(taken)):
            corners.append(int(i))
            taken.insert(k, float(arc[i]))
    return np.array(sorted(corners), dtype=int)


def _tangent_apex(before: np.ndarray, after: np.ndarray) -> np.ndarray | None:
    """Where the end tangent of `before` meets the start tangent of `after` (Bézier (K, 4, 2)),
    ahead of both; None when they are near parallel or meet behind either end.

    Near a sharp corner the medial axis bends away from the centre line (towards the
    inner corner's Voronoi region); the two straight-ish sides, extended, meet where the
    pen turned.
    """
    a, da = before[-1, 3], before[-1, 3] - before[-1, 2]
    b, db = after[0, 0], after[0, 1] - after[0, 0]
    matrix = np.column_stack([da, -db])
    if abs(np.linalg.det(matrix)) < 1e-9 * (np.linalg.norm(da) * np.linalg.norm(db) + 1e-12):
        return None
    s_a, s_b = np.linalg.solve(matrix, b - a)
    if s_a < 0 or s_b > 0:
        return None
    return a + s_a * da


def _corner_point(before: np.ndarray, after: np.ndarray, fallback: np.ndarray, limit: float) -> np.ndarray:
    """The tangents' meeting point (`_tangent_apex`), or `fallback` when there is none within
    `limit` px of it."""
    apex = _tangent_apex(before, after)
    if apex is None or np.linalg.norm(apex - fallback) > limit:
        return fallback
    return apex


def _distance_to_curve(piece: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(N,) px from each of `points` (N, 2) px to the curve of `piece` (K, 4, 2) px, sampled
    every `ink_guard.STEP` px."""
    return cKDTree(Stroke(piece).sample_evenly(STEP)).query(points)[0]


def _refit_dragged(pieces: list[np.ndarray], fitted: list[np.ndarray], cuts: list[int], xy: np.ndarray,
                   keep: np.ndarray, held: np.ndarray, corner: np.ndarray, twins: list[Twin], sigma: float,
                   stroke_width: float) -> None:
    """In place: a piece that a corner's joint dragged off its own points is refitted on them.

    A piece is fitted on its kept points, those a width or more from a corner, and its end
    is then moved to the corner point (where the sides' tangents meet, up to two widths out,
    or the tip the ink shows) with its inner handle kept. Moved that far, the end's first
    stretch swings off the points it was fitted on: up a band three passes share, where the
    way in's tangent at the band's foot points across it, the curve ran along the band's far
    edge, 2.5 px from its own centre line (a 2 px line). A piece that the joints moved more than
    `DRAGGED` widths farther from one of its kept points than its fit (`fitted`, the pieces
    before the joints) left it is refitted on them between its final ends, each point weighing
    what it weighed in the first fit (`held`). The fit's own residual is not a drag: bridging a
    shallow crossing's uncertain stretch, a long piece may pass half a width from the points
    beside it, and refitted, its crossing moved (pieces (K, 4, 2) px; cuts: the traced-point
    index each piece starts at, and the last).
    """
    for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:])):
        if not (corner[lo] or corner[hi]) or twin_piece(twins, lo, hi) is not None:
            continue
        kept = keep[lo + 1:hi]
        inner = xy[lo + 1:hi][kept]
        if not len(inner):
            continue
        off = _distance_to_curve(pieces[k], inner)
        if off.max() <= DRAGGED * stroke_width:
            continue
        if (off - _distance_to_curve(fitted[k], inner)).max() <= DRAGGED * stroke_width:
            continue
        # Writable, as every piece is: a retraced stretch's joints (`share_pieces`) and `_settle`
        # move its ends later (a piece of under four points comes back as a frozen Stroke's).
        pieces[k] = np.array(fit_piece(np.vstack([pieces[k][0, 0], inner, pieces[k][-1, 3]]), closed=False,
                                       sigma=sigma, held=np.concatenate([[1.0], held[lo + 1:hi][kept], [1.0]])))


def _reached_in_ink(guard: InkGuard, corner: np.ndarray, point: np.ndarray) -> bool:
    """Whether the straight way from the traced `corner` (2,) px to a corner point (2,) px
    lies in the ink: a spike out to the point and back is what the pen would draw.

    Held to the invariant's own slack (half width + 1 px), not to a thin line's one-width
    margin: the image probe finds little ink around a faint tip, and the centre-line point
    instead cuts the corner. The whole way, not the point alone: where a narrow loop's tip
    points at another stroke across a sliver of paper, its sides' tangents can meet in that
    stroke's ink, and the spike crossed the paper to them (3.05 px from the drawn line, a
    3.5 px line's bound 2.75).
    """
    count = int(np.ceil(np.linalg.norm(point - corner) / STEP)) + 1
    way = np.linspace(corner, point, count)
    return float(guard.excess(way).max()) <= MARGIN - guard.margin


def _open_fit(points: np.ndarray, sigma: float) -> np.ndarray:
    return fit_piece(points, closed=False, sigma=sigma, anchor=True)


def _settle(pieces: list[np.ndarray], cuts: list[int], xy: np.ndarray, twins: list[Twin],
            guard: InkGuard, sigma: float, inside: list[np.ndarray | None]) -> None:
    """In place, last: every piece of the curve as written lies in the ink.

    The joints move piece ends (to where two sides meet at a corner, to the middle of two
    ends), and the later pass of a retraced stretch drags its neighbours' ends onto the
    earlier pass's curve; either can swing a piece out that was checked when fitted (a
    corner cut across the paper, a loop's end pulled onto a spike's other joint). Each piece
    that strays now is refitted on all of its traced points between its final ends, so no
    joint moves again; a later pass takes its earlier twin's settled curve (settled first:
    it comes earlier) when their ends still agree. inside: per piece, the curve found in the
    ink when it was fitted (None: not checked there); a piece still equal to it is not
    measured again (the joints leave most pieces as they were).
    """
    index = {(lo, hi): k for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:]))}
    for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:])):
        source = twin_piece(twins, lo, hi)
        j = index.get(source[:2]) if source is not None else None
        if j is not None:
            copy = pieces[j][::-1, ::-1] if source[2] else pieces[j]
            if np.array_equal(copy[0, 0], pieces[k][0, 0]) and np.array_equal(copy[-1, 3], pieces[k][-1, 3]):
                pieces[k] = np.array(copy)
        if inside[k] is not None and np.array_equal(inside[k], pieces[k]):
            continue
        if curve_excess(guard, pieces[k])[0] <= 0.0:
            continue
        whole = xy[lo:hi + 1].copy()
        whole[0], whole[-1] = pieces[k][0, 0], pieces[k][-1, 3]
        pieces[k] = keep_in_ink(whole, _open_fit(whole, sigma), guard, _open_fit, sigma)


def _opened(points: np.ndarray, twins: list[Twin]) -> tuple[np.ndarray, list[Twin]]:
    """A closed line's (N,) `POINT` records (its first point repeated last or not), split
    somewhere, as an open line that starts and ends at its top-left split: (N', ) records
    whose last repeats the first, and the twins moved along.

    Where a closed line starts cannot be read from the ink; a pen usually starts at its
    top-left sharp feature: then the line is a chain of open pieces.
    """
    if np.allclose(points["xy"][0], points["xy"][-1]):
        last_corner = bool(points["corner"][-1])
        points = points[:-1]
        if not points["split"].any():  # the only split was the repeated point: it is the first
            points["split"][0] = True
            points["corner"][0] |= last_corner
    split_at = np.flatnonzero(points["split"])
    shift = int(split_at[np.argmin(points["xy"][split_at].sum(axis=1))])
    points = np.roll(points, -shift)
    twins = rolled(twins, shift, len(points))
    points = np.concatenate([points, points[:1]])
    return points, valid_twins(points["xy"], twins)


def fit_stroke(traced: TracedPoints, *, closed: bool, sigma: float, stroke_width: float,
               guard: InkGuard | None = None, twins: tuple[Twin, ...] = ()) -> Stroke:
    """Filter, split at sharp features (Y-feet tips, cusps, corners) and fit one traversed
    stroke; with `guard`, every piece is brought back inside the ink where it strays
    (`vectorize.fit.ink_guard`). twins: stretches the stroke draws twice (`vectorize.fit.retraces`):
    fitted once, the later pass repeats the earlier one's curve."""
    # One record per traced point (`traced.POINT`); the names below are views of its fields,
    # so marking one marks the points. Corners are found here (the traced ones join after).
    points = point_records(traced.xy, keep=traced.keep, split=traced.split, junction=traced.junction,
                           held=traced.held)
    xy, keep, split, corner = (points[name] for name in ("xy", "keep", "split", "corner"))
    arc = arc_lengths(xy)
    wide = _turn(xy, arc, 1.5 * stroke_width, closed) if len(xy) >= 5 else None
    found = _sharp_corners(xy, arc, wide, stroke_width, closed) if wide is not None else np.zeros(0, dtype=int)
    # A corner within a width of a split is the split's own turn (the route turning at a fork
    # is split there): the piece between them is a few tenths of a pixel long, and the
    # corner's joint, placed where its tangents meet, went 3 px off the line.
    found = found[keep[found] & (along_distance(arc, split)[found] > stroke_width)]
    corner[found] = True
    if guard is not None and wide is not None:
        # A cusp whose pruned spur left the axis's turn too round for a corner (`tips.pruned_cusps`).
        free = keep & ~split & ~points["junction"] & (along_distance(arc, corner) > 2.0 * stroke_width)
        corner[pruned_cusps(xy, arc, wide, free, guard, stroke_width, closed)] = True
    if traced.corner is not None:
        corner |= np.asarray(traced.corner, dtype=bool)
    split |= corner
    twins = valid_twins(xy, twins)
    mirror_flags(twins, split, corner)
    if closed and split.any() and len(points) > 3:
        points, twins = _opened(points, twins)
        closed = False
    if guard is not None:
        points, twins = with_fork_tips(points, twins, guard, stroke_width, closed)
        twins = valid_twins(points["xy"], twins)
    xy, keep, split, corner, junction, held = (points[name] for name in POINT.names)
    # Around a corner the axis is off the centre line for about a stroke width: leave it out.
    # (The corner joints below read the tip along this arc too.)
    arc = arc_lengths(xy)
    keep &= along_distance(arc, corner) > stroke_width
    mirror_keep(twins, keep)
    # Next to an uncertain stretch (a junction, a corner) the fit bridges a stretch without
    # points: there its shape, and where two passes cross, hangs on every point either side.
    dense = along_distance(arc, ~keep) <= DENSE * stroke_width
    cuts = [0] + [int(i) for i in np.flatnonzero(split) if 0 < i < len(xy) - 1] + [len(xy) - 1]
    pieces = []
    inside: list[np.ndarray | None] = []  # per piece: its curve when found in the ink (`_settle`)
    previous = None
    fitted: dict[tuple[int, int], int] = {}
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        source = twin_piece(twins, lo, hi)
        if source is not None and source[:2] in fitted:
            # The later pass over a retraced stretch: the earlier pass's curve.
            control = pieces[fitted[source[:2]]]
            pieces.append(np.array(control[::-1, ::-1] if source[2] else control))
            inside.append(None)
            previous = None
            continue
        mask = keep[lo:hi + 1].copy()
        if not closed:
            mask[0] = mask[-1] = True
            mask[0] &= not corner[lo]
            mask[-1] &= not corner[hi]
        piece, near, hold = xy[lo:hi + 1][mask], dense[lo:hi + 1][mask], held[lo:hi + 1][mask]
        if len(piece) < 2:
            piece, near, hold = xy[[lo, hi]], None, None
        if previous is not None and len(piece) == len(previous) and np.array_equal(piece, previous[::-1]):
            # The way back from a retraced spike: exactly the way out, reversed, so the
            # two passes lie on each other instead of crossing back and forth.
            control = pieces[-1][::-1, ::-1]
            checked = None
        else:
            settings = dict(closed=closed and len(cuts) == 2, sigma=sigma, anchor=not (corner[lo] or corner[hi]))
            # A long piece is first fitted on about one point per THIN widths away from its
            # uncertain stretches: FITPACK's time is linear in the points, and the axis gives
            # 3-5 per px. Where that fit leaves the ink, the piece is fitted on every point
            # before the guard's ladder: thinned knots can swing across a long uncertain stretch.
            spacing = min(THIN * stroke_width, THIN_MAX) if len(piece) > THIN_FROM else 0.0
            control = fit_piece(piece, **settings, spacing=spacing, dense=near, held=hold)
            worst = curve_excess(guard, control)[0] if guard is not None else 0.0
            checked = np.array(control) if guard is not None and worst <= 0.0 else None
            if worst > 0.0:
                if spacing:
                    control = fit_piece(piece, **settings, held=hold)
                # Measured against every traced point of the piece, the uncertain ones too.
                whole = xy[lo:hi + 1]
                if closed and len(cuts) == 2:
                    whole = np.vstack([whole, whole[:1]])
                control = keep_in_ink(whole, control, guard, _open_fit, sigma)
        previous = piece
        fitted[(lo, hi)] = len(pieces)
        pieces.append(np.array(control))  # writable: the joints move its ends
        inside.append(checked)
    as_fitted = [np.array(piece) for piece in pieces]
    # Join the pieces: at corners where their sides meet, elsewhere where they end.
    joints = list(zip(range(len(pieces) - 1), range(1, len(pieces)), cuts[1:-1]))
    if corner[0] and corner[-1] and len(pieces) > 1:
        joints.append((len(pieces) - 1, 0, 0))
    for k, m, at in joints:
        before, after = pieces[k], pieces[m]
        on_tangents = False
        if corner[at]:
            point = _corner_point(before, after, xy[at], 2.0 * stroke_width)
            on_tangents = guard is None or _reached_in_ink(guard, xy[at], point)
            if not on_tangents:
                point = xy[at]
            # Where the ink shows the pen went further than the tangents say (a narrow cusp
            # whose axis stops short), the tip goes there; the sides' handles follow it.
            # Not at a junction: beyond it lies the ink of the other branches, not a tip.
            tip = (corner_tip(xy, arc, at, guard, stroke_width, closed)
                   if guard is not None and not junction[at] else None)
            # Only a tip beyond the corner point by more than the invariant's slack moves it: a
            # sharp corner whose sides' tangents meet in the ink is already where the pen turned.
            if tip is not None and np.linalg.norm(tip - xy[at]) > np.linalg.norm(point - xy[at]) + MARGIN:
                point, on_tangents = tip, False
        else:
            point = (before[-1, 3] + after[0, 0]) / 2.0
        if not on_tangents or np.array_equal(point, xy[at]):
            # Elsewhere move the inner handles along, keeping both end tangents; at a
            # corner the point lies on the tangents already.
            before[-1, 2] += point - before[-1, 3]
            after[0, 1] += point - after[0, 0]
        before[-1, 3] = point
        after[0, 0] = point
    _refit_dragged(pieces, as_fitted, cuts, xy, keep, held, corner, twins, sigma, stroke_width)
    share_pieces(twins, cuts, pieces)
    if guard is not None and not (closed and len(pieces) == 1):  # a closed piece was checked when fitted
        _settle(pieces, cuts, xy, twins, guard, sigma, inside)
    control = np.concatenate(pieces, axis=0)
    return Stroke(control)
