"""The traced points of one stroke as the fit reads them (paper 3.4): where each point lies and
what the filter marked there, as the route hands them over (`TracedPoints`) and as
`fitting.fit_stroke` works on them (one `POINT` record per point)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# One traced point as `fitting.fit_stroke` holds it. An (N,) array of these is one thing per
# point that rolls, slices, inserts and closes as a whole, and each field (`points["keep"]`) is
# an (N,) view whose marks are the points' own:
#   xy (2,) px; keep: fitted (not an uncertain point near a crossing, a Y-foot or a corner);
#   split: the fit splits there; corner: a sharp corner (a split, and the joint goes where the
#   two sides' tangents meet); junction: a node of the axis where three or more branches
#   meet; held: how many points it weighs in the fit (`TracedPoints.held`).
# A structured array, not an object per point: a stroke has thousands of points.
POINT = np.dtype([("xy", np.float64, (2,)), ("keep", np.bool_), ("split", np.bool_), ("corner", np.bool_),
                  ("junction", np.bool_), ("held", np.float64)])


@dataclass(frozen=True, kw_only=True)
class TracedPoints:
    """The points of a traversed stroke with what the filter needs to know about each, as
    arrays (a stroke has thousands of points: one object per point cost more than the fit).

    xy: (N, 2) px; keep: (N,) bool, keep the point for the fit; split: (N,) bool, split the
    fit there; corner: (N,) bool or None (none), a corner (split, and the joint goes where
    the two sides' tangents meet); radius: (N,) px, the medial axis's distance to the
    outline at each point (half the ink width), or None (unknown); junction: (N,) bool or
    None (none), the point is a node of the axis where three or more branches meet; held:
    (N,) how many points each weighs in the fit (a crossing node kept alone in its uncertain
    zone stands for the points dropped there), or None (one each).
    """

    xy: np.ndarray
    keep: np.ndarray
    split: np.ndarray
    corner: np.ndarray | None = None
    radius: np.ndarray | None = None
    junction: np.ndarray | None = None
    held: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.xy)


def point_records(xy, *, keep=True, split=False, corner=False, junction=False, held=1.0) -> np.ndarray:
    """(N,) `POINT` records of the points `xy` ((N, 2) px) with the given marks: each an (N,)
    array or one value for every point (None: the default)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    points = np.zeros(len(xy), dtype=POINT)
    points["xy"] = xy
    for name, value, default in (("keep", keep, True), ("split", split, False), ("corner", corner, False),
                                 ("junction", junction, False), ("held", held, 1.0)):
        points[name] = default if value is None else value
    return points
