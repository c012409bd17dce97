"""Rows on the files' 0.1 mm grid: stitches too short merged away, moves too long split.

The planner snaps its needle points to the grid first; these rules then hold for the
points the machine will sew (see `plan`).
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from fabrication.embroidery.needles import BODY, LOCK, MOTIF, STITCH, TRAVEL, UNDERLAY

# Needle points the min-stitch rule may drop: body points, never tacks or locks.
_DROPPABLE = np.zeros(8, dtype=bool)
_DROPPABLE[[BODY, UNDERLAY, MOTIF, TRAVEL]] = True


def merge_short(units: np.ndarray, kinds: np.ndarray, roles: np.ndarray, min_units: float) -> np.ndarray:
    """Keep-mask: drop zero-length stitches anywhere and body stitches shorter than
    `min_units` (grid units). When the short stitch ends a body (the lock's anchor), the
    body point before it goes instead. Only short places are visited, in row order; the
    previous kept row is found through pointers that skip dropped rows with path
    compression, so the work stays near linear however many rows merge (a run of a
    million tiny stitches included)."""
    n = len(units)
    sewn = np.zeros(n, dtype=bool)
    sewn[1:] = (kinds[1:] == STITCH) & (kinds[:-1] == STITCH)
    d = np.full(n, np.inf)
    d[1:] = np.hypot(*(units[1:] - units[:-1]).T)
    work = np.flatnonzero(sewn & ((d == 0) | ((d < min_units) & _DROPPABLE[roles]))).tolist()
    if not work:
        return np.ones(n, dtype=bool)
    heapq.heapify(work)
    # Plain Python lists: the loop touches single rows, where numpy scalars are slow.
    ux, uy = units[:, 0].tolist(), units[:, 1].tolist()
    kind, role = kinds.tolist(), roles.tolist()
    droppable = _DROPPABLE.tolist()
    kept = [True] * n
    # below[i]: a row at or before i - 1 from which the search for the kept row before i
    # starts; dropped rows are skipped and the pointers shortened on the way.
    below = list(range(-1, n - 1))

    def previous_kept(i: int) -> int:
        k = below[i]
        trail = []
        while not kept[k]:
            trail.append(k)
            k = below[k]
        for j in trail:
            below[j] = k
        below[i] = k
        return k

    while work:
        i = heapq.heappop(work)
        if not kept[i]:
            continue
        k = previous_kept(i)
        if kind[k] != STITCH or kind[i] != STITCH:
            continue
        dist = math.hypot(ux[i] - ux[k], uy[i] - uy[k])
        if dist == 0:
            kept[i] = False
        elif dist < min_units and droppable[role[i]]:
            anchor = i + 1 < n and role[i + 1] == LOCK and kind[i + 1] == STITCH
            if not anchor:
                kept[i] = False
            elif droppable[role[k]] and k > 0 and kind[previous_kept(k)] == STITCH:
                kept[k] = False  # the lock's anchor stays; the body point before it goes
                heapq.heappush(work, i)
                continue
            else:
                # The body shrank to one short stitch: drop its end, the lock stands in.
                kept[i] = False
        else:
            continue
        if i + 1 < n:
            heapq.heappush(work, i + 1)  # the next stitch now starts further back
    return np.array(kept, dtype=bool)


def split_long(units: np.ndarray, kinds: np.ndarray, params: np.ndarray,
               max_units: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split needle-down moves longer than `max_units` per axis into real stitches, on the
    grid. Returns the new units (M, 2), params (M,) and the row (M,) each new row comes
    from (to carry the other per-row arrays along: `kinds[source]`, ...)."""
    sewn = np.zeros(len(units), dtype=bool)
    sewn[1:] = (kinds[1:] == STITCH) & (kinds[:-1] == STITCH)
    step = np.zeros(len(units), dtype=np.int64)
    step[1:] = np.abs(np.diff(units, axis=0)).max(axis=1)
    pieces = np.where(sewn, -(-step // max_units), 1)
    pieces = np.maximum(pieces, 1)
    if pieces.max() == 1:
        return units, params, np.arange(len(units))
    # Row i becomes pieces[i] rows: intermediate points on the way from row i - 1.
    owner = np.repeat(np.arange(len(units)), pieces)
    k = np.arange(owner.size) - np.repeat(np.cumsum(pieces) - pieces, pieces) + 1
    frac = k / pieces[owner]
    prev = units[np.maximum(owner - 1, 0)]
    # floor(k * d / n) steps differ by at most ceil(d / n) <= max_units per axis.
    new_units = prev + np.floor((units[owner] - prev) * frac[:, None] + 0.5).astype(np.int64)
    # A row's last piece is the row itself, with its own parameter (the row before may be a
    # jump or trim, whose parameter is NaN: it must not reach the rows after it).
    prev_param = params[np.maximum(owner - 1, 0)]
    last = k == pieces[owner]
    new_params = np.where(last, params[owner], prev_param + (params[owner] - prev_param) * np.where(last, 0.0, frac))
    return new_units, new_params, owner
