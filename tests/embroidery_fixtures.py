"""Drawings in mm for the embroidery tests, and checks every stitch file must pass."""

from __future__ import annotations

import numpy as np

from fabrication.embroidery.needles import LOCK, TACK
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, StitchPlan
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

STYLE_NAMES = ("running", "triple", "zigzag", "arrows")
FORMATS = ("pes", "dst", "jef", "exp", "vp3")


def spiral(cx: float, cy: float, r0: float, r1: float, turns: float, n: int = 24) -> Stroke:
    """A smooth spiral as cubic segments (Hermite to Bézier), radius r0 -> r1 mm."""
    th = np.linspace(0.0, 2 * np.pi * turns, n + 1)
    r = r0 + (r1 - r0) * th / th[-1]
    p = np.c_[cx + r * np.cos(th), cy + r * np.sin(th)]
    dr = (r1 - r0) / th[-1]
    d = np.c_[dr * np.cos(th) - r * np.sin(th), dr * np.sin(th) + r * np.cos(th)]  # dp/dtheta
    h = np.diff(th)[:, None] / 3.0
    control = np.stack([p[:-1], p[:-1] + d[:-1] * h, p[1:] - d[1:] * h, p[1:]], axis=1)
    return Stroke(control)


def s_curve_with_corner() -> Stroke:
    """Two smooth cubic arcs, then a sharp (about 120 degree) corner into a straight leg."""
    control = np.array([
        [[-40, -20], [-30, -45], [-10, -45], [0, -20]],
        [[0, -20], [10, 5], [30, 5], [35, -20]],
        [[35, -20], [30, -23], [25, -26], [20, -29]],
    ], dtype=float)
    return Stroke(control)


def design() -> Drawing:
    """Four strokes in mm around (0, 0): an S with a corner, a spiral 2 mm after it ends
    (joined by a travel stitch), a far straight line (trim + jump) and a short wiggle."""
    first = s_curve_with_corner()
    end = first.end
    second = spiral(end[0] - 2.0 - 4.0, end[1], 4.0, 9.0, 1.5)  # starts 2 mm left of `end`
    third = Stroke.from_polyline(np.array([[-35.0, 30.0], [10.0, 38.0]]))
    fourth = spiral(25.0, 30.0, 2.0, 5.0, 1.0, n=12)
    return Drawing((first, second, third, fourth), 100, 100, "mm")


def needle_runs(plan: StitchPlan) -> list[np.ndarray]:
    """Row indices of each run of consecutive needle-down rows."""
    needle = plan.kinds == STITCH
    edges = np.flatnonzero(np.diff(np.concatenate([[0], needle.astype(int), [0]])))
    return [np.arange(a, b) for a, b in zip(edges[::2], edges[1::2])]


def sewn_stitches(plan: StitchPlan) -> np.ndarray:
    """(S, 2) per-axis deltas of every needle-down stitch of a plan or a file read back."""
    a, b = plan.stitches()
    return b - a


def stroke_rows(plan: StitchPlan) -> dict[int, np.ndarray]:
    """Needle rows of each stroke of a planned plan, in order."""
    rows = np.flatnonzero(plan.kinds == STITCH)
    return {int(k): rows[plan.strokes[rows] == k] for k in np.unique(plan.strokes[rows])}


def lock_figure_ok(points: np.ndarray) -> bool:
    """Five needle points [e, a, b, a, e] of a half-stitch lock or tack: out and back,
    every stitch non-zero."""
    if len(points) != 5:
        return False
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    return bool(np.allclose(points[0], points[4]) and np.allclose(points[1], points[3])
                and steps.min() > 0)


# -- what an embroiderer checks: piled-up holes -------------------------------------------
PENETRATION_GAP = 0.2  # mm: a needle this close to a recent hole on its side re-pierces it
PENETRATION_WINDOW = 4  # "the previous few" needle points


def needle_sides(plan: StitchPlan, *, centre: float = 0.15) -> np.ndarray:
    """Side of the curve of each row: +1 left, -1 right, 0 on the curve (within `centre`
    mm), from the sewn stroke at the row's parameter (rows without a stroke: 0)."""
    sides = np.zeros(len(plan.points), dtype=int)
    sewn = plan.sewn
    for k in np.unique(plan.strokes[plan.strokes >= 0]):
        rows = np.flatnonzero(plan.strokes == k)
        t = np.clip(plan.params[rows] - k, 0.0, 1.0)
        stroke = sewn.strokes[int(k)]
        offset = plan.points[rows] - stroke.points_at(t)
        tangent = stroke.tangents_at(t)
        cross = tangent[:, 0] * offset[:, 1] - tangent[:, 1] * offset[:, 0]
        far = np.linalg.norm(offset, axis=1) > centre
        sides[rows] = np.where(far, np.sign(cross), 0).astype(int)
    return sides


def repeated_penetrations(plan: StitchPlan, *, gap: float = PENETRATION_GAP,
                          window: int = PENETRATION_WINDOW) -> int:
    """Needle points outside tacks and locks that land within `gap` mm of one of the
    previous `window` needle points on the same side of the curve (same run of thread)."""
    sides = needle_sides(plan)
    count = 0
    for run in needle_runs(plan):
        pts, side, role = plan.points[run], sides[run], plan.roles[run]
        for lag in range(1, window + 1):
            if len(run) <= lag:
                break
            close = np.linalg.norm(pts[lag:] - pts[:-lag], axis=1) < gap - 1e-9
            same = side[lag:] == side[:-lag]
            free = (role[lag:] != TACK) & (role[lag:] != LOCK)
            count += int((close & same & free).sum())
    return count


def worst_density(plan: StitchPlan, radius: float = 0.5) -> int:
    """Most needle points within `radius` mm of a needle point, both outside tacks and
    locks (measured independently of `embroidery_stats`)."""
    from scipy.spatial import cKDTree

    needle = plan.kinds == STITCH
    pts, roles = plan.points[needle], plan.roles[needle]
    sewn = pts[(roles != TACK) & (roles != LOCK)]
    return int(cKDTree(sewn).query_ball_point(sewn, radius, return_length=True).max())
