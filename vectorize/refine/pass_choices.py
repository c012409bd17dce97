"""The user's side of a triple point (three passes through one node, six branches).

An edit names a pairing of the six branches by their directions leaving the node (degrees,
0 = +x, 90 = +y: down the image), so that it survives renumbered slots and small changes
of the algorithm: each direction of the edit goes to the nearest branch, one branch each.
The page offers the pairings under which the line is still drawn in one stroke, likeliest
first (by the pass scorer's posterior, or by continuation when no scorer ran).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from vectorize.axis.clusters import Pairs, matchings
from vectorize.route.route_inspection import pieces

# A direction of an edit further than this from every free branch matches nothing (degrees).
MAX_ANGLE_ERROR = 45.0


def foot_angles(dirs: np.ndarray) -> np.ndarray:
    """(D,) directions of the branches leaving a node, degrees in [0, 360), 0.1 degree steps
    (as the edits file keeps them); dirs (D, 2) unit tangents in px (x right, y down)."""
    return np.round(np.degrees(np.arctan2(dirs[:, 1], dirs[:, 0])) % 360.0, 1) % 360.0


def as_angles(pairs: Pairs, angles: np.ndarray) -> list[list[float]]:
    """Slot pairs as pairs of directions (degrees), each pair and the list sorted."""
    return sorted(sorted([float(angles[a]), float(angles[b])]) for a, b in pairs)


def slots_of(passes, angles: np.ndarray) -> Pairs | None:
    """The slot pairs that `passes` (pairs of directions, degrees) name at a node whose
    branches leave at `angles`; None when the counts differ or a direction is off by more
    than MAX_ANGLE_ERROR."""
    wanted = np.array([a for pair in passes for a in pair], dtype=float)
    if len(wanted) != len(angles):
        return None
    gap = np.abs(wanted[:, None] - angles[None, :]) % 360.0
    gap = np.minimum(gap, 360.0 - gap)
    rows, cols = linear_sum_assignment(gap)
    if gap[rows, cols].max() > MAX_ANGLE_ERROR:
        return None
    slot = dict(zip(rows.tolist(), cols.tolist()))
    return tuple(sorted(tuple(sorted((slot[2 * k], slot[2 * k + 1]))) for k in range(len(passes))))


def normal(pairs: Pairs) -> Pairs:
    return tuple(sorted(tuple(sorted(p)) for p in pairs))


def chance_of(pairs: Pairs, posterior: np.ndarray | None) -> float | None:
    """The posterior of pairing `pairs` (slot pairs), or None without one."""
    if posterior is None:
        return None
    every = [normal(p) for p in matchings(list(range(2 * len(pairs))))]
    return round(float(posterior[every.index(normal(pairs))]), 4)


def pass_options(graph, node: int, dirs: np.ndarray, posterior: np.ndarray | None, decided: dict,
                 one_piece: bool) -> list[tuple[Pairs, float | None]]:
    """The pairings of `node` worth offering, likeliest first, with their posterior (None
    without a scorer: then ranked by continuation, straightest first).

    decided: node -> slot pairs of every other decided junction (crossings and triple
    points), as the drawing shows them; one_piece: keep only the pairings under which the
    drawing stays one line (single-line mode).
    """
    every = list(matchings(list(range(len(dirs)))))
    # Bending: the sum over passes of 1 + cos between the two feet (0 = all straight).
    bend = np.array([sum(1.0 + float(np.dot(dirs[a], dirs[b])) for a, b in p) for p in every])
    known = posterior is not None and len(posterior) == len(every)
    score = np.asarray(posterior, dtype=float) if known else np.zeros(len(every))
    result = []
    for k in np.lexsort((bend, -score)):  # likeliest first, then straightest
        pairs = normal(every[k])
        if one_piece and pieces(graph, {**decided, node: pairs}) != 1:
            continue
        result.append((pairs, round(float(score[k]), 4) if known else None))
    return result
