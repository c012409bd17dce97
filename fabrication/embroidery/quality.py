"""What an embroiderer checks on a stitch plan, measured one way for everyone: needle
density with every needle point counted (tacks and locks included) and repeated holes.

The planner (adapting tacks and locks), the stats and their warnings, the tests and
`benchmarks/embroidery_quality.py` all call these functions, so the number a user is
shown is the number the benchmark reports.

- Density: how many needle points lie within `radius` mm (inclusive) of a needle point,
  itself included. Ink/Stitch's density map flags 6 or more within 0.5 mm; we warn above
  `DENSITY_LIMIT` = 6.
- Repeated holes: a needle point (outside tacks and locks, which re-enter their holes on
  purpose) landing within `HOLE_GAP` mm of one of the previous `HOLE_WINDOW` needle
  points of its run of thread, on the same side of the curve: the needle cuts or piles
  the threads already in that hole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from fabrication.embroidery.needles import LOCK, STITCH, TACK

DENSITY_RADIUS = 0.5  # mm
DENSITY_LIMIT = 6  # needle points within DENSITY_RADIUS; more is too dense
HOLE_GAP = 0.2  # mm: a needle this close to a recent hole on its side re-pierces it
HOLE_WINDOW = 4  # how many previous needle points count as "recent"
# Points on the 0.1 mm grid lie exactly 0.5 mm apart (0.3, 0.4): they count as within.
_EPS = 1e-9


@dataclass(frozen=True, kw_only=True)
class Place:
    """A place on the design: x, y in mm (the plan's frame: centred, y down) and the
    count found there (needle points within the radius, or repeated holes)."""

    x: float
    y: float
    count: int

    def __str__(self) -> str:
        return f"({self.x:.1f}, {self.y:.1f}) mm"


@dataclass(frozen=True, kw_only=True)
class Density:
    """maximum: most needle points within `radius` mm of one needle point (itself
    included); dense: needle points with more than `limit`; places: the dense places,
    densest first, one per cluster (points of one cluster lie within 2 x radius of its
    centre)."""

    maximum: int
    dense: int
    places: tuple[Place, ...]
    radius: float
    limit: int


def density_counts(points: np.ndarray, at: np.ndarray | None = None, *,
                   radius: float = DENSITY_RADIUS) -> np.ndarray:
    """Needle points of `points` (N, 2) mm within `radius` mm of each point of `at`
    (M, 2) mm (default: `points` themselves, each counting itself); (M,) int."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    centres = points if at is None else np.asarray(at, dtype=float).reshape(-1, 2)
    if not len(points) or not len(centres):
        return np.zeros(len(centres), dtype=np.int64)
    return np.asarray(cKDTree(points).query_ball_point(centres, radius + _EPS, return_length=True),
                      dtype=np.int64)


def needle_density(points: np.ndarray, *, radius: float = DENSITY_RADIUS,
                   limit: int = DENSITY_LIMIT) -> Density:
    """The density of needle points `points` (N, 2) mm, every one counted."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if not len(points):
        return Density(maximum=0, dense=0, places=(), radius=radius, limit=limit)
    tree = cKDTree(points, balanced_tree=False, compact_nodes=False)  # 3x quicker to build, queried once
    # The limit + 1 nearest tell whether a point is dense (4x cheaper than counting all
    # neighbours of 100,000 points); only dense ones are counted in full.
    k = min(limit + 1, len(points))
    distance, _ = tree.query(points, k=k, distance_upper_bound=radius + _EPS)
    counts = np.isfinite(distance.reshape(len(points), -1)).sum(axis=1)
    over = np.flatnonzero(counts > limit)
    if len(over):
        counts[over] = tree.query_ball_point(points[over], radius + _EPS, return_length=True)
    return Density(maximum=int(counts.max()), dense=len(over),
                   places=_places(points[over], counts[over], 2 * radius), radius=radius, limit=limit)


def _places(points: np.ndarray, counts: np.ndarray, reach: float) -> tuple[Place, ...]:
    """One place per cluster of `points`: the densest point (first in sewing order on a
    tie), then the densest of those further than `reach` from every place so far."""
    if not len(points):
        return ()
    order = np.lexsort((np.arange(len(counts)), -counts))
    tree = cKDTree(points)
    places: list[Place] = []
    taken = np.zeros(len(points), dtype=bool)
    for i in order.tolist():
        if taken[i]:
            continue
        places.append(Place(x=float(points[i, 0]), y=float(points[i, 1]), count=int(counts[i])))
        taken[tree.query_ball_point(points[i], reach + _EPS)] = True
    return tuple(places)


def needle_sides(plan, *, centre: float = 0.15) -> np.ndarray:
    """(N,) side of the curve of each row of `plan` (a `StitchPlan` with `sewn` strokes):
    +1 left, -1 right, 0 on the curve (within `centre` mm) or on rows without a stroke."""
    sides = np.zeros(len(plan.points), dtype=int)
    if plan.sewn is None:
        return sides
    for k in np.unique(plan.strokes[plan.strokes >= 0]):
        rows = np.flatnonzero(plan.strokes == k)
        sides[rows] = stroke_sides(plan.sewn.strokes[int(k)], plan.points[rows], plan.params[rows] - k,
                                   centre=centre)
    return sides


def stroke_sides(stroke, points: np.ndarray, t: np.ndarray, *, centre: float = 0.15) -> np.ndarray:
    """(N,) int side of `stroke` of needle points `points` (N, 2) mm made at its parameters
    `t` (N,): +1 left, -1 right, 0 within `centre` mm of the curve."""
    t = np.clip(t, 0.0, 1.0)
    offset = points - stroke.points_at(t)
    tangent = stroke.tangents_at(t)
    cross = tangent[:, 0] * offset[:, 1] - tangent[:, 1] * offset[:, 0]
    far = np.linalg.norm(offset, axis=1) > centre
    return np.where(far, np.sign(cross), 0).astype(int)


def repeated_holes(plan, *, gap: float = HOLE_GAP, window: int = HOLE_WINDOW) -> np.ndarray:
    """Rows of `plan` (a `StitchPlan`) whose needle re-enters a recent hole: outside tacks
    and locks, within `gap` mm of one of the previous `window` needle points of the same
    run of thread on the same side of the curve. Sorted row indices."""
    needle = plan.kinds == STITCH
    sides = needle_sides(plan)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], needle.astype(int), [0]])))
    found = []
    for a, b in zip(edges[::2], edges[1::2]):
        pts, side, role = plan.points[a:b], sides[a:b], plan.roles[a:b]
        free = (role != TACK) & (role != LOCK)
        hit = np.zeros(b - a, dtype=bool)
        for lag in range(1, min(window, b - a - 1) + 1):
            close = np.linalg.norm(pts[lag:] - pts[:-lag], axis=1) < gap - _EPS
            hit[lag:] |= close & (side[lag:] == side[:-lag]) & free[lag:]
        found.append(a + np.flatnonzero(hit))
    return np.concatenate(found) if found else np.zeros(0, dtype=np.int64)


def hole_places(plan, rows: np.ndarray) -> tuple[Place, ...]:
    """The repeated holes at `rows` of `plan` grouped into places (1 mm apart), most first."""
    if not len(rows):
        return ()
    points = plan.points[rows]
    counts = density_counts(points, radius=2 * DENSITY_RADIUS)
    return _places(points, counts, 2 * DENSITY_RADIUS)


def where(places: tuple[Place, ...], most: int = 12) -> str:
    """Where a warning's problem lies: every place, 'at (x, y) mm (8), (x, y) mm (7)'; past
    `most` places, how many and the first `most` of them: 'at 15 places, the first 12: ...'."""
    shown = ", ".join(f"{p} ({p.count})" for p in places[:most])
    if len(places) <= most:
        return f"at {shown}"
    return f"at {len(places)} places, the first {most}: {shown}"
