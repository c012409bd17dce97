"""Checks every stitch plan must pass: needle runs, each stroke's rows, lock figures, piled-up
holes and density, measured on a planned `StitchPlan` or a file read back."""

from __future__ import annotations

import numpy as np

from fabrication.embroidery.plan import STITCH, StitchPlan


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


# -- what an embroiderer checks: piled-up holes and density ---------------------------------
# One implementation, the library's (`fabrication.embroidery.quality`): the stats' warnings,
# the planner and benchmarks/embroidery_quality.py measure the same way.


def repeated_penetrations(plan: StitchPlan, **kwargs) -> int:
    """How many needle points re-enter a recent hole (see `quality.repeated_holes`)."""
    from fabrication.embroidery.quality import repeated_holes

    return len(repeated_holes(plan, **kwargs))


def worst_density(plan: StitchPlan, radius: float = 0.5) -> int:
    """Most needle points within `radius` mm of a needle point, every needle point counted
    (tacks and locks too): a brute-force count over all pairs, independent of the
    k-d tree in `quality.needle_density` that the stats use."""
    pts = plan.points[plan.kinds == STITCH]
    worst = 0
    for start in range(0, len(pts), 512):
        d = np.linalg.norm(pts[start:start + 512, None] - pts[None], axis=2)
        worst = max(worst, int((d <= radius + 1e-9).sum(axis=1).max()))
    return worst
