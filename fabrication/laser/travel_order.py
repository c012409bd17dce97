"""Order and direction of strokes that keep laser travel (beam-off moves) short.

A greedy nearest-end tour from the machine position, then 2-opt on the open path: reversing
a run of the tour also flips each stroke in it, which changes only the two travel moves at
the run's ends, so every candidate costs O(1) and one sweep over all runs is vectorized.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from onestroke.progress import ProgressCallback, Stage


@dataclass(frozen=True)
class TravelOrder:
    """order: stroke indices in job order; flipped: True where a stroke runs end to start.

    Travel lengths in the caller's unit: in the input order and direction (`before`),
    after the greedy tour (`greedy`) and after 2-opt (`after`); all start at `origin`.
    """

    order: np.ndarray
    flipped: np.ndarray
    before: float
    greedy: float
    after: float


def travel_length(starts: np.ndarray, ends: np.ndarray, origin: np.ndarray) -> float:
    """Travel of strokes taken in the given order: origin -> start0, end_k -> start_k+1."""
    if len(starts) == 0:
        return 0.0
    prev = np.vstack([origin[None, :], ends[:-1]])
    return float(np.linalg.norm(starts - prev, axis=1).sum())


def _greedy(starts: np.ndarray, ends: np.ndarray, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = len(starts)
    tree = cKDTree(np.vstack([starts, ends]))
    used = np.zeros(n, dtype=bool)
    order = np.empty(n, dtype=int)
    flipped = np.zeros(n, dtype=bool)
    position = origin
    for step in range(n):
        k = 8
        while True:
            _, idx = tree.query(position, k=min(k, 2 * n))
            idx = np.atleast_1d(idx)
            free = idx[~used[idx % n]]
            if len(free) or k >= 2 * n:
                break
            k *= 4
        pick = int(free[0])
        stroke = pick % n
        used[stroke] = True
        order[step] = stroke
        flipped[step] = pick >= n
        position = starts[stroke] if flipped[step] else ends[stroke]
    return order, flipped


def _two_opt(starts: np.ndarray, ends: np.ndarray, origin: np.ndarray, order: np.ndarray,
             flipped: np.ndarray, *, max_sweeps: int, window: int, report: Stage) -> tuple[np.ndarray, np.ndarray]:
    # S[k], E[k]: entry and exit point of the k-th stroke of the tour as currently oriented.
    S = np.where(flipped[:, None], ends[order], starts[order])
    E = np.where(flipped[:, None], starts[order], ends[order])
    order, flipped = order.copy(), flipped.copy()
    n = len(order)
    for _ in range(max_sweeps):
        improved = False
        gained = 0.0
        for i in range(n):
            report.advance()
            P = origin if i == 0 else E[i - 1]
            hi = min(n, i + window)
            j = np.arange(i, hi)
            Ej = E[i:hi]
            has_next = j + 1 < n
            Nj = S[np.minimum(j + 1, n - 1)]
            old = np.linalg.norm(P - S[i]) + np.where(has_next, np.linalg.norm(Ej - Nj, axis=1), 0.0)
            new = np.linalg.norm(Ej - P, axis=1) + np.where(has_next, np.linalg.norm(S[i] - Nj, axis=1), 0.0)
            gain = old - new
            best = int(np.argmax(gain))
            if gain[best] > 1e-9:
                gained += float(gain[best])
                jj = i + best
                S[i:jj + 1], E[i:jj + 1] = E[i:jj + 1][::-1].copy(), S[i:jj + 1][::-1].copy()
                order[i:jj + 1] = order[i:jj + 1][::-1]
                flipped[i:jj + 1] = ~flipped[i:jj + 1][::-1]
                improved = True
        # stop when a sweep gains less than 0.1 % of the travel: later sweeps gain even less
        total = travel_length(S, E, origin)
        if not improved or gained < 1e-3 * total:
            break
    return order, flipped


def order_strokes(starts: np.ndarray, ends: np.ndarray, *, origin=(0.0, 0.0), max_sweeps: int = 30,
                  window: int | None = None, progress: ProgressCallback | None = None) -> TravelOrder:
    """Choose an order and direction of strokes that minimises travel.

    starts, ends: (n, 2) first and last point of each stroke. origin: (2,) where the head
    is before the job. 2-opt considers runs of up to `window` strokes (default: 1000,
    fewer for thousands of strokes to bound the work) and stops after `max_sweeps` sweeps
    or when a sweep gains less than 0.1 %; no randomness, so the result is deterministic.
    progress: an `onestroke.progress.ProgressCallback` (strokes looked at, over the most
    sweeps allowed: a run that stops early jumps to 100 %).
    """
    starts = np.asarray(starts, dtype=float).reshape(-1, 2)
    ends = np.asarray(ends, dtype=float).reshape(-1, 2)
    origin = np.asarray(origin, dtype=float)
    n = len(starts)
    if window is None:
        window = int(min(1000, max(100, 500_000 // max(n, 1))))
    before = travel_length(starts, ends, origin)
    if n == 0:
        return TravelOrder(np.zeros(0, int), np.zeros(0, bool), 0.0, 0.0, 0.0)
    order, flipped = _greedy(starts, ends, origin)
    S = np.where(flipped[:, None], ends[order], starts[order])
    E = np.where(flipped[:, None], starts[order], ends[order])
    greedy = travel_length(S, E, origin)
    report = Stage(progress, "ordering strokes", n * max_sweeps, "strokes")
    order, flipped = _two_opt(starts, ends, origin, order, flipped, max_sweeps=max_sweeps, window=window,
                              report=report)
    report.finish()
    S = np.where(flipped[:, None], ends[order], starts[order])
    E = np.where(flipped[:, None], starts[order], ends[order])
    after = travel_length(S, E, origin)
    return TravelOrder(order, flipped, before, greedy, after)
