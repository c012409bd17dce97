"""The curve never leaves the ink: measure a fitted piece against the medial balls, refit it
closer, split it, or in the end follow the centre line itself.

The ink is the union of its medial balls (each centre-line point with its radius), so a
point p lies within the ink grown by `margin` px exactly when |p - q| - r(q) <= margin for
some centre-line point q. A smooth spline fitted through two passes of a retraced stem, or
pulled across a sharp turn, can swing outside; the ladder below brings it back, each rung
tighter than the one before: refit with every point and little smoothing; split at the
worst point and fit the halves; the centre line as a polyline.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import shapely
from scipy.ndimage import map_coordinates
from scipy.spatial import cKDTree

from vectorize.axis.graph import MedialGraph
from vectorize.stroke import Stroke

# Nearest centre-line points looked at per sample: a ball further down the list than this
# is smaller than a nearer one's (they are 0.25-1 px apart along the line).
NEIGHBOURS = 8
SPLIT_DEPTH = 4
# A curve is checked at points at most STEP px apart along a polyline within FLATNESS px of
# it. The excess is 1-Lipschitz (moving a point by d changes it by at most d), so between
# two checked points it exceeds the larger of theirs by at most STEP / 2 + FLATNESS.
FLATNESS = 0.1
STEP = 0.4
# The invariant: every point within half the local width + SLACK px of the centre line.
# Checked points must keep the sampling error in hand: the guard's margin is what is left.
SLACK = 1.0
MARGIN = SLACK - STEP / 2 - FLATNESS
# Outline samples looked at per point about a merged cluster (`merged_radii`).
NEAREST_SAMPLES = 4
# Nor more than one width away: for lines under 2 px wide that is the nearer bound.
MIN_MARGIN = 0.05


def guard_margin(stroke_width: float) -> float:
    """The guard's margin (px) for lines `stroke_width` px wide: the invariant's slack, at
    most half the width (so no point strays more than one width from the centre line), less
    the sampling error of the check."""
    return max(min(SLACK, 0.5 * stroke_width) - STEP / 2 - FLATNESS, MIN_MARGIN)


def curve_points(control: np.ndarray) -> np.ndarray:
    """Points along a Bézier spline ((K, 4, 2)) no more than `STEP` px apart: (N, 2).

    The vertices of a flattening alone are not enough: a straight piece flattens to its two
    ends, and a chord across a corner of the drawing would be checked only where it meets
    the ink.
    """
    polyline = Stroke(control).flatten(FLATNESS)
    # A piece shrunk to a point (GEOS cannot segmentize a line of no length) is its point.
    if len(polyline) < 2 or not (polyline != polyline[0]).any():
        return polyline
    return shapely.get_coordinates(shapely.segmentize(shapely.linestrings(polyline), STEP))


class InkGuard:
    """How far points lie outside the ink grown by `margin` px (<= 0: inside).

    graph: the centre line with radii; gray, level: the working image and its ink
    threshold. Pruning leaves the tips of sharp corners uncovered by medial balls, so a
    point the balls miss is looked up in the image itself (with its `margin` around it).
    """

    def __init__(self, graph: MedialGraph, gray: np.ndarray, level: float, *, margin: float = MARGIN,
                 rings: Sequence[np.ndarray] = ()) -> None:
        self.gray, self.level = gray, level
        points = [b.points for b in graph.branches.values()]
        radii = [b.radii for b in graph.branches.values()]
        if graph.positions:
            points.append(np.array(list(graph.positions.values())))
            radii.append(np.array(list(graph.radii.values())))
        self.points = np.vstack(points) if points else np.zeros((1, 2))
        self.radii = np.concatenate(radii) if radii else np.zeros(1)
        self.tree = cKDTree(self.points)
        if len(rings):
            self.radii = merged_radii(graph, self.tree, self.radii, rings)
        self.margin = margin
        # A point farther than this from every centre-line point is outside all the balls
        # grown by the margin: `strays` stops its search for the nearest one there.
        self.reach = float(self.radii.max()) + margin

    def excess(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) points -> (N,) px beyond the grown ink (negative inside)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        k = min(NEIGHBOURS, len(self.points))
        dist, index = self.tree.query(xy, k=k)
        dist, index = dist.reshape(len(xy), k), index.reshape(len(xy), k)
        excess = (dist - self.radii[index]).min(axis=1) - self.margin
        out = np.flatnonzero(excess > 0.0)
        if out.size:
            angles = np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False)
            ring = np.vstack([[0.0, 0.0], self.margin * np.column_stack([np.cos(angles), np.sin(angles)])])
            probe = (xy[out, None, :] + ring[None]).reshape(-1, 2)
            h, w = self.gray.shape
            values = map_coordinates(self.gray, [np.clip(probe[:, 1], 0, h - 1), np.clip(probe[:, 0], 0, w - 1)],
                                     order=1, mode="nearest").reshape(len(out), len(ring))
            excess[out[(values < self.level).any(axis=1)]] = 0.0
        return excess

    def beyond_balls(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) points -> (N,) px beyond the nearest medial ball, ungrown (<= 0: some ball
        holds the point). Ink beyond every ball is ink the centre line does not hold: the
        tip of a sharp corner whose spur was pruned."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        k = min(NEIGHBOURS, len(self.points))
        dist, index = self.tree.query(xy, k=k)
        return (dist.reshape(len(xy), k) - self.radii[index.reshape(len(xy), k)]).min(axis=1)

    def strays(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) points -> (N,): `excess` where a point lies outside the grown ink (> 0, the
        same number); where it lies inside, some number <= 0 (not its excess).

        Enough to tell whether a curve leaves the ink, how far at most and where, at less
        than half the cost: the nearest ball alone holds most points (its distance less its
        radius bounds the excess from above), and only the others are checked in full.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        # Searched only within `reach` (a third less work): a point with no centre-line point
        # that near is outside (index: the tree's size) and checked in full like any other.
        dist, index = self.tree.query(xy, k=1, distance_upper_bound=self.reach)
        index = np.asarray(index).reshape(len(xy))
        far = index == len(self.points)
        bound = np.asarray(dist, dtype=float).reshape(len(xy)) - self.radii[np.where(far, 0, index)]
        bound -= self.margin
        bound[far] = np.inf
        check = np.flatnonzero(bound > 0.0)
        if check.size:
            bound[check] = self.excess(xy[check])
        return bound

    def stroke_excess(self, stroke: Stroke) -> float:
        """Largest excess along a stroke (px), checked every `STEP` px (`curve_points`)."""
        return float(self.excess(curve_points(stroke.control)).max())


def merged_radii(graph: MedialGraph, tree: cKDTree, radii: np.ndarray, rings: Sequence[np.ndarray]) -> np.ndarray:
    """`radii` (N,) of the centre-line points in `tree`, with those about merged junction
    clusters measured to the ink's outline (`rings`: closed polylines (M, 2) of outline samples).

    A merged cluster's node sits at one place of its ink (where the passes cross) and carries
    its junctions' largest radius, and the straight runs that join it to the old junctions
    carry theirs: balls that may reach over paper, a hole between passes for one. There the
    radius is each point's distance to the outline.
    """
    merged = [(graph.positions[n], span) for n, span in graph.spans.items() if n in graph.positions]
    near = [i for centre, span in merged for i in tree.query_ball_point(centre, span + 0.5)]
    rings = [r for r in rings if len(r) > 1]
    if not near or not rings:
        return radii
    samples = np.vstack(rings)
    # Each sample's next along its ring: the outline's segments are (sample, next).
    starts = np.cumsum([0] + [len(r) for r in rings[:-1]])
    following = np.arange(len(samples)) + 1
    following[starts + [len(r) - 1 for r in rings]] = starts
    preceding = np.empty_like(following)
    preceding[following] = np.arange(len(samples))
    # The nearest segment has an end among a point's nearest samples: measure the segments
    # on either side of its NEAREST_SAMPLES nearest. (An unbalanced tree builds in half the time.)
    at = tree.data[near]
    nearest = cKDTree(samples, balanced_tree=False, compact_nodes=False).query(at, k=NEAREST_SAMPLES)[1]
    ends = np.concatenate([np.stack([nearest, following[nearest]], axis=-1),
                           np.stack([preceding[nearest], nearest], axis=-1)], axis=1)  # (P, 2k, 2)
    a, b = samples[ends[..., 0]], samples[ends[..., 1]]
    ab = b - a
    t = np.clip(((at[:, None] - a) * ab).sum(axis=2) / np.maximum((ab * ab).sum(axis=2), 1e-12), 0.0, 1.0)
    radii = radii.copy()
    radii[near] = np.linalg.norm(at[:, None] - (a + t[..., None] * ab), axis=2).min(axis=1)
    return radii


def curve_excess(guard: InkGuard, control: np.ndarray) -> tuple[float, np.ndarray]:
    """Largest excess of a piece and where it is, when the piece leaves the ink (> 0);
    a number <= 0 when it does not (`InkGuard.strays`)."""
    pts = curve_points(control)
    ex = guard.strays(pts)
    k = int(np.argmax(ex))
    return float(ex[k]), pts[k]


def keep_in_ink(points: np.ndarray, control: np.ndarray, guard: InkGuard,
                fit: Callable[[np.ndarray, float], np.ndarray], sigma: float,
                depth: int = 0) -> np.ndarray:
    """A fit of `points` (N, 2), the piece's whole traced centre line, that stays in the ink.

    control: (K, 4, 2) the first fit; fit(points, sigma) -> control fits an open piece
    anchored at its ends. Returns control points (K', 4, 2) whose curve lies within the
    guard's margin of the ink wherever the centre line itself does.
    """
    worst, at = curve_excess(guard, control)
    if worst <= 0.0 or len(points) < 3:
        return control
    # The centre line itself may run outside (a bridged pen gap): then only do as well.
    allowed = max(0.0, float(guard.strays(points).max()))
    if worst <= allowed + 1e-6:
        return control
    tight = fit(points, 0.25 * sigma)
    tight_worst, at = curve_excess(guard, tight)
    if tight_worst <= allowed + 1e-6:
        return tight
    if depth < SPLIT_DEPTH and len(points) >= 8:
        # Split at the traced point nearest the worst place, away from the piece's ends.
        k = int(np.argmin(np.linalg.norm(points - at, axis=1)))
        k = min(max(k, 2), len(points) - 3)
        left, right = points[:k + 1], points[k:]
        first = keep_in_ink(left, fit(left, sigma), guard, fit, sigma, depth + 1)
        second = keep_in_ink(right, fit(right, sigma), guard, fit, sigma, depth + 1)
        return np.concatenate([first, second], axis=0)
    return Stroke.from_polyline(points).control
