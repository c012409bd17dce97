"""TSP art as benchmark drawings: one closed line through thousands of stipple points.

The method of Kaplan and Bosch (2005), as TSP-art tools do it:

1. a tone image: a smooth random field plus a few soft dark blobs, on a grid of 4 px cells;
2. stippling: points drawn with density proportional to the darkness, then spread by
   weighted Lloyd relaxation (Secord 2002: each point moves to the darkness-weighted
   centroid of its Voronoi cell, cells found with a k-d tree on the grid);
3. a tour: nearest neighbour, improved by 2-opt over each point's 10 nearest neighbours
   until no move shortens it, then every remaining pair of crossing edges is uncrossed by
   the 2-opt move between them (which always shortens the tour): the line never crosses
   itself;
4. legibility: where two parts of the line that are not neighbours along it come closer
   than the width + 2 px (centre to centre: less than one clear pixel of paper between
   their ink) or a corner is sharper than 25 degrees, the offending point leaves the tour,
   and steps 3-4 repeat until none is left.

So the drawing is one closed polyline of 2500-4500 corners with no crossing and passes
running 1-3 px of paper apart wherever the tone is dark (near-touches everywhere); width
2-3.5 px. Ground truth: the tour (closed, any start, either direction), no intersections;
narrow corners are don't-care zones.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy import ndimage
from scipy.spatial import cKDTree

from benchmarks.metrics.ground_truth import CANVAS, MARGIN, GroundTruth
from benchmarks.sets.hershey import _sharp_turns
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

CELL = 4.0  # px per tone-image cell
MIN_CORNER = 25.0  # degrees: sharper corners are dropped from the tour
NEIGHBOURS = 10  # 2-opt candidates per point


def tone_image(rng: np.random.Generator, size: int) -> np.ndarray:
    """Darkness (size, size) in [0.05, 1]: a smooth field and a few soft dark blobs."""
    field = ndimage.gaussian_filter(rng.normal(size=(size, size)), size / 8)
    field = (field - field.min()) / (np.ptp(field) + 1e-12)
    yy, xx = np.mgrid[0:size, 0:size] / size
    for _ in range(rng.integers(2, 5)):
        cx, cy, r = rng.uniform(0.2, 0.8), rng.uniform(0.2, 0.8), rng.uniform(0.08, 0.25)
        field += rng.uniform(0.5, 1.0) * np.exp(-((xx - cx) ** 2 + (yy - cy) ** 2) / (2 * r * r))
    field = (field - field.min()) / (np.ptp(field) + 1e-12)
    return 0.05 + 0.95 * field ** 1.5


def stipple(rng: np.random.Generator, tone: np.ndarray, count: int, iterations: int = 8) -> np.ndarray:
    """`count` points (cell units) with density following `tone`, spread by weighted Lloyd
    relaxation."""
    h, w = tone.shape
    cells = np.c_[np.indices((h, w)).reshape(2, -1)[::-1].T + 0.5]
    weight = tone.ravel()
    pick = rng.choice(len(weight), size=count, replace=False, p=weight / weight.sum())
    points = cells[pick] + rng.uniform(-0.5, 0.5, (count, 2))
    for _ in range(iterations):
        _, owner = cKDTree(points).query(cells)
        mass = np.bincount(owner, weight, minlength=count)
        moved = np.c_[np.bincount(owner, weight * cells[:, 0], minlength=count),
                      np.bincount(owner, weight * cells[:, 1], minlength=count)]
        has = mass > 0
        points[has] = moved[has] / mass[has, None]
    return points


def nearest_neighbour_tour(points: np.ndarray) -> np.ndarray:
    """A closed tour (indices) built by always walking to the nearest unvisited point."""
    n = len(points)
    left = np.ones(n, dtype=bool)
    tour = np.empty(n, dtype=int)
    current = 0
    for k in range(n):
        tour[k] = current
        left[current] = False
        if k == n - 1:
            break
        d = np.einsum("ij,ij->i", points - points[current], points - points[current])
        d[~left] = np.inf
        current = int(np.argmin(d))
    return tour


def _reverse(tour: np.ndarray, pos: np.ndarray, i: int, j: int) -> None:
    """2-opt move: reverse tour[i+1 .. j] (cyclic indices, i before j), in place."""
    n = len(tour)
    length = (j - i) % n
    if length * 2 > n:  # reverse the other side instead: the same cycle, less work
        i, j = j, i + n
        length = n - length
    idx = np.arange(i + 1, i + 1 + length) % n
    tour[idx] = tour[idx[::-1]]
    pos[tour[idx]] = idx


def two_opt(points: np.ndarray, tour: np.ndarray, max_passes: int = 30) -> np.ndarray:
    """2-opt over each point's nearest neighbours until no move shortens the tour."""
    tour = tour.copy()
    n = len(tour)
    pos = np.empty(n, dtype=int)
    pos[tour] = np.arange(n)
    _, near = cKDTree(points).query(points, k=min(NEIGHBOURS + 1, n))
    pts = points.tolist()

    def dist(a: int, b: int) -> float:
        return ((pts[a][0] - pts[b][0]) ** 2 + (pts[a][1] - pts[b][1]) ** 2) ** 0.5

    for _ in range(max_passes):
        improved = False
        for a in range(n):
            for c in near[a, 1:]:
                i, j = int(pos[a]), int(pos[c])
                b, d = int(tour[(i + 1) % n]), int(tour[(j + 1) % n])
                if c == b or d == a:
                    continue
                if dist(a, b) + dist(c, d) - dist(a, c) - dist(b, d) > 1e-9:
                    _reverse(tour, pos, i, j)
                    improved = True
        if not improved:
            break
    return tour


def _edges(points: np.ndarray, tour: np.ndarray) -> np.ndarray:
    return np.stack([points[tour], points[np.roll(tour, -1)]], axis=1)


def uncross(points: np.ndarray, tour: np.ndarray, limit: int = 10_000) -> np.ndarray:
    """Uncross every pair of crossing edges by the 2-opt move between them."""
    tour = tour.copy()
    n = len(tour)
    pos = np.empty(n, dtype=int)
    pos[tour] = np.arange(n)
    for _ in range(limit):
        lines = shapely.linestrings(_edges(points, tour))
        left, right = shapely.STRtree(lines).query(lines, predicate="crosses")
        apart = (right - left) % n > 1
        pairs = np.c_[left, right][(left < right) & apart & ((left - right) % n > 1)]
        if not len(pairs):
            return tour
        i, j = (int(v) for v in pairs[0])
        _reverse(tour, pos, i, j)
    raise RuntimeError("tour still crosses itself")


def _too_close(points: np.ndarray, tour: np.ndarray, clearance: float) -> set[int]:
    """Tour positions to drop: a point on the nearer end of two non-neighbouring edges closer
    than `clearance`, and corners sharper than MIN_CORNER."""
    n = len(tour)
    seg = _edges(points, tour)
    lines = shapely.linestrings(seg)
    left, right = shapely.STRtree(lines).query(lines, predicate="dwithin", distance=clearance)
    keep = (left < right) & ((right - left) % n > 1) & ((left - right) % n > 1)
    drop: set[int] = set()
    for i, j in zip(left[keep], right[keep]):
        if i in drop or j in drop or (i + 1) % n in drop or (j + 1) % n in drop:
            continue
        # the end point of either edge lying closest to the other edge leaves the tour
        ends = [(shapely.distance(shapely.Point(seg[i][e]), lines[j]), (i + e) % n) for e in (0, 1)]
        ends += [(shapely.distance(shapely.Point(seg[j][e]), lines[i]), (j + e) % n) for e in (0, 1)]
        drop.add(min(ends)[1])
    u = seg[:, 1] - seg[:, 0]
    prev = np.roll(u, 1, axis=0)
    cos = -np.einsum("ij,ij->i", prev, u) / (np.linalg.norm(prev, axis=1) * np.linalg.norm(u, axis=1) + 1e-12)
    drop |= set(np.flatnonzero(cos > np.cos(np.radians(MIN_CORNER))).tolist())
    return drop


def tsp_tour(rng: np.random.Generator, count: int, width: float, box: float, gap: float = 2.0) -> np.ndarray:
    """A legible closed tour (module doc) as a closed polyline (M + 1, 2) in px, in [0, box]^2;
    `gap`: px of paper kept between the ink of two passes (centre lines width + gap apart)."""
    size = int(box / CELL)
    points = stipple(rng, tone_image(rng, size), count) * CELL
    tour = two_opt(points, nearest_neighbour_tour(points))
    for _ in range(50):
        tour = uncross(points, tour)
        drop = _too_close(points, tour, width + gap)
        if not drop:
            poly = points[tour]
            return np.vstack([poly, poly[:1]])
        points = points[np.delete(tour, sorted(drop))]
        tour = two_opt(points, np.arange(len(points)), max_passes=3)
    raise RuntimeError("no legible tour")


def tsp_drawing(seed: int, index: int) -> GroundTruth:
    """One TSP-art drawing, determined by (seed, index)."""
    rng = np.random.default_rng([seed, index, 53])
    width = float(np.round(rng.uniform(2.0, 3.5) * 4) / 4)
    count = int(rng.integers(2500, 4500))
    box = CANVAS - 2 * (MARGIN + width + 10)
    poly = tsp_tour(rng, count, width, box) + (CANVAS - box) / 2
    stroke = Stroke.from_polyline(poly)
    drawing = Drawing((stroke,), CANVAS, CANVAS, unit="px", stroke_width=width)
    return GroundTruth(name=f"tsp-{seed}-{index}", kind="tsp", drawing=drawing, closed=True,
                       intersections=np.zeros((0, 2)), events=(),
                       dont_care=tuple(_sharp_turns(poly, True, width)),
                       meta={"seed": seed, "index": index, "width": width, "points": len(poly) - 1,
                             "stipples": count})
