"""The paths route inspection draws twice, between odd nodes, over the branches themselves.

A decided junction (a crossing or a touch at a degree-4 node) says how the drawing's own
passes go through it: which two branch ends are one pass. A path drawn twice is a pass more,
which that decision does not describe. It follows the decided pass where that is about as
short, and turns at the junction where the line is much shorter that way: a d whose bowl
touches its stem retraces the stem and turns into its bowl's top at the touch, instead of
drawing the whole bowl again because the touch's pairing continues the stem into the bowl.

The shortest paths run over a graph whose vertices are the undecided nodes and the ends of
the branches at decided nodes: a branch joins its two ends at its cost, a decided junction
joins the ends it pairs at no cost and two others at their turn's price (`turn_prices`):
`PER_NAT` widths per unit of -log plausibility by which the junction's classification
prefers its decided pairing over the pairing that makes that turn (nothing where the turn's
pairing is as plausible: a touch read as continuing where the line could turn), plus a
smoothness tie-break of `TURN` widths, more as the turn is sharper. So a turn where the
classifier is sure the line goes straight through (a crossing at 0.98: ~4-6 units) is taken
only where it saves 12-18 widths of retracing or more: a d's retraced bowl saves 15-70, while
a word's lead-in and the bottom of its first loop, retraced through the crossing between them
so that the line may start at a stem's tip instead, save up to 13 (the line is then no
shorter to speak of, and its order is wrong). Three passes through one point keep their
passes (no turn there).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import slots
from vectorize.route.traversal import Pass

TURN = 0.25  # widths: a retraced path's turn at a decided junction, plus as much again for its bend
PER_NAT = 3.0  # widths of retrace a turn must save per unit of -log plausibility against it


def turn_prices(ranked: dict, costs: dict, pairing: dict, stroke_width: float) -> dict[int, dict[tuple[int, int], float]]:
    """Decided degree-4 node -> {(slot a, slot b), a < b: px a retraced path's turn between them
    costs} for every pair its decided pairing does not join (module doc).

    ranked[node]: its pairings, preferred first; costs[node]: -log plausibility of each;
    pairing: node -> its decided pairing (a pairing the user fixed has no alternatives: no turn).
    """
    prices = {}
    for node, chosen in pairing.items():
        base = costs[node][ranked[node].index(chosen)]
        prices[node] = {tuple(sorted(pair)): PER_NAT * stroke_width * max(cost - base, 0.0)
                        for option, cost in zip(ranked[node], costs[node]) if option != chosen for pair in option}
    return prices


def turns_at(graph: MedialGraph, decided: dict, step: Pass, after: Pass) -> bool:
    """Whether the line turns where `step` ends and `after` begins: at a decided junction
    (decided: node -> its slot pairs), out by a branch end its pairing does not join to the
    one it came in by (a retraced path's turn). The fit splits there, as at a cusp."""
    node = graph.branches[step.branch].node(step.end)
    if node not in decided:
        return False
    node_slots = slots(graph, node)
    into, out = node_slots.index((step.branch, step.end)), node_slots.index((after.branch, after.start))
    return not any({into, out} == set(pair) for pair in decided[node])


class RetracePaths:
    """Shortest paths between the odd nodes of one piece of the graph (module doc).

    graph: the branch graph; partner: decided node -> {slot: partner slot}; cost_of: the
    piece's branches, branch id -> px its retrace costs; odd: the odd nodes
    (graph ids, undecided); directions: node -> (D, 2) unit tangents per slot (nodes of
    degree >= 3; missing ones count as a right-angle turn); stroke_width: px; prices:
    `turn_prices` (decided nodes left out, or pairs, allow no turn).
    """

    def __init__(self, graph: MedialGraph, partner: dict[int, dict[int, int]], cost_of: dict[int, float],
                 odd: list[int], directions: dict, stroke_width: float, prices: dict) -> None:
        self.graph = graph
        self.decided = partner
        self._slots: dict[int, list] = {}
        ids: dict[tuple[int, int], int] = {}

        def vertex(node: int, slot: int) -> int:
            return ids.setdefault((node, slot if node in partner else -1), len(ids))

        self.sources = [vertex(n, 0) for n in odd]
        # The cheapest link between two vertices: (cost, branch id or -1 for a turn, end at the first vertex).
        best: dict[tuple[int, int], tuple[float, int, str]] = {}

        def link(x: int, y: int, cost: float, bid: int, end_at_x: str) -> None:
            if x == y or not np.isfinite(cost):
                return  # a loop at an undecided node never shortens a path; a turn not allowed
            key, end = ((x, y), end_at_x) if x < y else ((y, x), "b" if end_at_x == "a" else "a")
            if key not in best or cost < best[key][0]:
                best[key] = (cost, bid, end)

        for bid in sorted(cost_of):
            branch = graph.branches[bid]
            link(vertex(branch.a, self.slot(branch.a, bid, "a")), vertex(branch.b, self.slot(branch.b, bid, "b")),
                 cost_of[bid], bid, "a")
        w = stroke_width
        for node, pairs in partner.items():
            dirs = directions.get(node)
            degree = graph.degree(node)
            for a in range(degree):
                for b in range(a + 1, degree):
                    if (node, a) not in ids or (node, b) not in ids:
                        continue
                    bend = 1.0 + float(np.dot(dirs[a], dirs[b])) if dirs is not None else 1.0
                    price = prices.get(node, {}).get((a, b), np.inf)
                    cost = 0.0 if pairs.get(a) == b else price + TURN * w * (1.0 + bend)
                    link(ids[node, a], ids[node, b], cost, -1, "a")
        self.best = best
        keys = list(best)
        # scipy drops stored zeros: a free link costs a hair above nothing.
        weights = [max(best[k][0], 1e-9) for k in keys]
        n = len(ids)
        matrix = coo_matrix((weights, ([k[0] for k in keys], [k[1] for k in keys])), shape=(n, n)).tocsr()
        self.dist, self.pred = dijkstra(matrix, directed=False, indices=self.sources, return_predecessors=True)

    def slot(self, node: int, bid: int, end: str) -> int:
        """The slot of branch end (bid, end) at `node` (`simplify.slots` order)."""
        if node not in self._slots:
            self._slots[node] = slots(self.graph, node)
        return self._slots[node].index((bid, end))

    def step(self, x: int, y: int) -> Pass | None:
        """The branch pass from vertex x to the adjacent vertex y (None: a turn or a decided pass)."""
        cost, bid, end = self.best[(x, y) if x < y else (y, x)]
        if bid < 0:
            return None
        if x > y:
            end = "b" if end == "a" else "a"
        return Pass(bid, end)

    def path(self, i: int, j: int) -> tuple[Pass, ...]:
        """The branch passes from odd node i to odd node j (indices into `odd`), in order."""
        seq = [self.sources[j]]
        while seq[-1] != self.sources[i]:
            seq.append(int(self.pred[i, seq[-1]]))
        seq.reverse()
        return tuple(p for p in (self.step(x, y) for x, y in zip(seq[:-1], seq[1:])) if p is not None)

    def legs(self, i: int, j: int) -> list[tuple[tuple[Pass, ...], tuple[int, int], tuple[int, int]]]:
        """The path from odd node i to odd node j cut at the undecided nodes it passes: per leg
        its passes, (node, slot) where it begins and (node, slot) where it ends. The walk may
        take each leg at its own time, as it does the drawing's own chains."""
        result, current, begin = [], [], None
        for p in self.path(i, j):
            branch = self.graph.branches[p.branch]
            if begin is None:
                node = branch.node(p.start)
                begin = (node, self.slot(node, p.branch, p.start))
            current.append(p)
            far = branch.node(p.end)
            if far not in self.decided:
                result.append((tuple(current), begin, (far, self.slot(far, p.branch, p.end))))
                current, begin = [], None
        return result

    def first_slots(self, first: np.ndarray, i: int, j: int) -> tuple[int, int]:
        """The slots at odd nodes i and j by which the path between them leaves i and reaches j.

        first: (M, V) the vertex after each source on its shortest path (`_first_steps`)."""
        a, b = self.sources[i], self.sources[j]
        out = self.step(a, int(first[i, b]))
        into = self.step(int(self.pred[i, b]), b)
        return self._slot(out, start=True), self._slot(into, start=False)

    def _slot(self, p: Pass, *, start: bool) -> int:
        end = p.start if start else p.end
        return self.slot(self.graph.branches[p.branch].node(end), p.branch, end)
