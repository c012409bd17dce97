"""Which odd nodes the retraced paths join, and where the pen starts and ends: one matching.

Route inspection pairs the odd-degree nodes of a graph by paths drawn twice; a single line
may also leave two of them unpaired as its two ends. Both choices are one minimum-weight
perfect matching, solved exactly by Edmonds' blossom algorithm (networkx), on the odd nodes
plus two "end" vertices: each end vertex is joined to every odd node at the cost of the pen
starting or ending there, and the two end vertices to each other at 0 (a closed line, when
that is cheaper or there is nothing to leave unpaired). A perfect matching then pairs every
odd node with another one or with an end vertex: at most two ends, never one.

Weights are integers (1/`SCALE` px): blossom is exact on integers, and ties are decided by
the graph's insertion order, the same on every run.

Above `PRUNE_FROM` vertices only edges that can be in an optimal matching go to blossom
(networkx's is O(n^3) in pure Python: 0.5 s CPU on 100 odd nodes and all their pairs, here).
For any node potentials y and any perfect matching M, cost(M) = sum(y) + sum over M of the
reduced costs r(u, v) = c(u, v) - y(u) - y(v). With y from the linear programme's dual (the
fractional matching bound, scipy's HiGHS), r >= 0, so an edge whose r exceeds U - sum(y),
U the cost of any perfect matching, is in no matching cheaper than U: it is left out. The
blossom optimum on what is left is the optimum of the whole problem.
"""

from __future__ import annotations

import numpy as np

SCALE = 1000  # integer weight units per px
PRUNE_FROM = 32  # vertices (odd nodes + 2) from which edges are pruned by their reduced cost


def match_odd(cost: np.ndarray, end_cost: np.ndarray) -> tuple[list[tuple[int, int]], list[int]]:
    """Pairs of odd nodes to join by retraced paths, and the (0 or 2) left for the pen's ends.

    cost: (M, M) symmetric px, the cost of joining two odd nodes (inf where no path does);
    end_cost: (M,) px, the cost of the pen starting or ending at each (may be negative: an
    end the user asked for). M is even. Minimises the pairs' costs plus the ends' exactly.
    Returns (pairs (i, j) with i < j, sorted; ends, sorted).
    """
    m = len(cost)
    if m == 0:
        return [], []
    if m == 2:
        # The problem's perfect matchings are the pair (and the end vertices together) or the
        # two ends: compared directly, ends first at a tie (networkx's import costs more
        # than most drawings' whole route).
        pair, ends = np.rint(cost[0, 1] * SCALE), np.rint((end_cost[0] + end_cost[1]) * SCALE)
        return ([(0, 1)], []) if pair < ends else ([], [0, 1])
    n = m + 2
    first, second = np.triu_indices(m, 1)
    linked = np.isfinite(cost[first, second])
    first, second = first[linked], second[linked]
    odd = np.arange(m)
    # odd-odd pairs, then each odd node to end vertex m and to m + 1, then m to m + 1
    rows = np.r_[first, odd, odd, m]
    cols = np.r_[second, np.full(m, m), np.full(m, m + 1), m + 1]
    px = np.r_[cost[first, second], end_cost, end_cost, 0.0]
    w = np.rint(px * SCALE).astype(np.int64)
    mate = _blossom(rows, cols, w) if n < PRUNE_FROM else _pruned(n, rows, cols, w)
    pairs = sorted((min(u, v), max(u, v)) for u, v in mate if u < m and v < m)
    pen_ends = sorted(min(u, v) for u, v in mate if (u < m) != (v < m))
    return pairs, pen_ends


def _blossom(rows: np.ndarray, cols: np.ndarray, w: np.ndarray) -> list[tuple[int, int]]:
    """networkx's minimum-weight maximum-cardinality matching over the edges given."""
    from onestroke.lasting import import_later

    nx = import_later("networkx")  # for good in a command (onestroke/lasting.py)
    graph = nx.Graph()
    graph.add_weighted_edges_from(zip(rows.tolist(), cols.tolist(), w.tolist()))
    return [(int(u), int(v)) for u, v in nx.min_weight_matching(graph)]


def _pruned(n: int, rows: np.ndarray, cols: np.ndarray, w: np.ndarray) -> list[tuple[int, int]]:
    """The blossom optimum over the edges whose reduced cost leaves them a chance (module doc)."""
    from scipy.optimize import linprog
    from scipy.sparse import coo_matrix

    k = len(w)
    incidence = coo_matrix((np.ones(2 * k), (np.r_[np.arange(k), np.arange(k)], np.r_[rows, cols])), shape=(k, n))
    dual = linprog(-np.ones(n), A_ub=incidence.tocsr(), b_ub=w.astype(float), bounds=(None, None), method="highs")
    if dual.status != 0:
        return _blossom(rows, cols, w)
    y = dual.x
    reduced = w - y[rows] - y[cols]
    # The bound holds for any y; a slightly infeasible one (r < 0 by rounding) only widens it.
    slack = n / 2 * max(0.0, -float(reduced.min())) + 1.0
    weight = {(int(u), int(v)): int(x) for u, v, x in zip(rows, cols, w)}
    # A first perfect matching from the tightest edges (about 3 per vertex) and each vertex's
    # 3 cheapest by reduced cost; its cost U bounds which edges the optimum may use (on the
    # cursive set's lines the first is usually the last).
    keep = (reduced <= max(1.0, float(np.sort(reduced)[min(k - 1, 3 * n)]))) | _cheapest_at(n, rows, cols, reduced, 3)
    while True:
        mate = _blossom(rows[keep], cols[keep], w[keep])
        if 2 * len(mate) == n or keep.all():
            break
        keep = reduced <= float(np.sort(reduced)[min(k - 1, 2 * int(keep.sum()))])  # twice as many
    bound = sum(weight[min(u, v), max(u, v)] for u, v in mate) - float(y.sum()) + slack
    wider = reduced <= bound
    if not np.any(wider & ~keep):
        return mate
    return _blossom(rows[wider], cols[wider], w[wider])


def _cheapest_at(n: int, rows: np.ndarray, cols: np.ndarray, values: np.ndarray, count: int) -> np.ndarray:
    """(k,) bool: the edges among the `count` smallest `values` at either of their vertices."""
    ends = np.r_[rows, cols]
    edge = np.r_[np.arange(len(rows)), np.arange(len(rows))]
    order = np.lexsort((np.r_[values, values], ends))
    start = np.searchsorted(ends[order], np.arange(n))
    rank = np.arange(len(order)) - start[ends[order]]
    chosen = np.zeros(len(rows), dtype=bool)
    chosen[edge[order[rank < count]]] = True
    return chosen
