"""Graph ordering (paper 3.3.2): walk the simplified graph into strokes, in drawing order.

The walk starts at an end of the drawing and follows branches; at a degree-4 node it
leaves by the branch the chosen pairing assigns, at a Y-junction it goes down the foot
and back, at other nodes it goes as straight as it can. When a single-line drawing comes
out as several strokes, some degree-4 decision was wrong: a best-first search over the
alternatives, cheapest (least confident) first, looks for a one-stroke ordering.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from vectorize.graph import MedialGraph
from vectorize.intersections import Pairing
from vectorize.simplify import Simplified, Slot, directions, slots

# Bound of the retry search: traversals tried before giving up on one stroke.
MAX_TRAVERSALS = 400


@dataclass(frozen=True)
class Pass:
    """One traversal of a branch: branch id and the end it starts from ("a" or "b")."""

    branch: int
    start: str


@dataclass(frozen=True)
class Ordering:
    """Strokes as sequences of branch passes; `choice` is the pairing used per crossing."""

    strokes: tuple[tuple[Pass, ...], ...]
    closed: tuple[bool, ...]
    choice: tuple


class Walker:
    """Walks one graph under one assignment of pairings to its degree-4 nodes."""

    def __init__(self, graph: MedialGraph, simple: Simplified, stroke_width: float) -> None:
        self.graph = graph
        self.simple = simple
        self.slots = {n: slots(graph, n) for n in graph.incident}
        self.index = {n: {s: i for i, s in enumerate(sl)} for n, sl in self.slots.items()}
        self.dirs = {n: directions(graph, n, 2.5 * stroke_width) for n in graph.incident
                     if graph.degree(n) >= 3}
        # Y-feet are drawn out and back: they may be walked twice.
        self.allowed = {bid: 1 for bid in graph.branches}
        for node, foot in simple.y_feet.items():
            self.allowed[self.slots[node][foot][0]] = 2

    def ends(self) -> list[tuple[int, int]]:
        """(node, slot) where strokes may start: free ends and stroke-ending junctions."""
        result = []
        for node in sorted(self.graph.incident):
            degree = self.graph.degree(node)
            if degree == 1 and node not in self.simple.y_tips:
                result.append((node, 0))
            elif node in self.simple.t_ends:
                # Leave along the branch outside the smoothest pair (the pair with the
                # largest angle between them is walked through later, in one go).
                d = self.dirs[node]
                pairs = [(float(np.dot(d[i], d[j])), k) for i, j, k in ((0, 1, 2), (0, 2, 1), (1, 2, 0))]
                result.append((node, min(pairs)[1]))
        return result

    def _exit(self, node: int, entry: int, used: dict, pairing: dict) -> int | None:
        degree = self.graph.degree(node)
        node_slots = self.slots[node]

        def free(i: int) -> bool:
            bid = node_slots[i][0]
            return used[bid] < self.allowed[bid]

        if degree == 1:
            return entry if node in self.simple.y_tips and free(entry) else None
        if degree == 2:
            other = 1 - entry
            return other if free(other) else None
        if node in self.simple.y_feet:
            foot = self.simple.y_feet[node]
            if entry != foot and free(foot):
                return foot
            rest = [i for i in range(3) if i not in (entry, foot) and free(i)]
            return rest[0] if rest else None
        if degree == 4 and node in pairing:
            (a, b), (c, d) = pairing[node]
            partner = {a: b, b: a, c: d, d: c}[entry]
            return partner if free(partner) else None
        # Any other junction: go as straight as possible among free branches.
        options = [i for i in range(degree) if i != entry and free(i)]
        if not options:
            return None
        d = self.dirs[node]
        return min(options, key=lambda i: float(np.dot(d[entry], d[i])))

    def _walk(self, node: int, out: int, used: dict, pairing: dict) -> tuple[list[Pass], bool]:
        path: list[Pass] = []
        start = (node, out)
        while True:
            bid, end = self.slots[node][out]
            if used[bid] >= self.allowed[bid]:
                return path, False
            used[bid] += 1
            path.append(Pass(bid, end))
            branch = self.graph.branches[bid]
            far_end = "b" if end == "a" else "a"
            node = branch.b if end == "a" else branch.a
            entry = self.index[node][(bid, far_end)]
            out = self._exit(node, entry, used, pairing)
            if out is None:
                # Back where we began? Then the first branch is used up, but the rules
                # would take it again: the stroke is a closed loop.
                first = path[0].branch
                used[first] -= 1
                again = self._exit(node, entry, used, pairing)
                used[first] += 1
                return path, (node, again) == start
            if (node, out) == start:
                return path, True

    def traverse(self, pairing: dict) -> tuple[list[list[Pass]], list[bool]]:
        """All strokes for one assignment of pairings: from ends first, then closed loops."""
        used = {bid: 0 for bid in self.graph.branches}
        strokes, closed = [], []
        for node, out in self.ends():
            if used[self.slots[node][out][0]] < self.allowed[self.slots[node][out][0]]:
                path, _ = self._walk(node, out, used, pairing)
                if path:
                    strokes.append(path)
                    closed.append(False)
        for bid in sorted(self.graph.branches):
            while used[bid] < self.allowed[bid]:
                branch = self.graph.branches[bid]
                node = branch.a
                out = self.index[node][(bid, "a")]
                path, is_loop = self._walk(node, out, used, pairing)
                if not is_loop:
                    # Not a loop: also walk backwards from where we started and join.
                    entry = self.index[node][(bid, "a")]
                    back_out = self._exit(node, entry, used, pairing)
                    if back_out is not None:
                        back, _ = self._walk(node, back_out, used, pairing)
                        path = [Pass(p.branch, "b" if p.start == "a" else "a") for p in reversed(back)] + path
                strokes.append(path)
                closed.append(is_loop)
        return strokes, closed


def order_strokes(graph: MedialGraph, simple: Simplified, ranked: dict[int, tuple[Pairing, ...]],
                  costs: dict[int, tuple[float, ...]], *, stroke_width: float, search: bool) -> tuple[Ordering, int]:
    """Traverse with the preferred pairings; if that gives several strokes and `search`,
    try alternatives best-first by total cost. Returns the ordering and traversals tried.

    ranked[node]: the three pairings of a degree-4 node, preferred first; costs[node]: the
    cost of choosing each (0 for the first, higher for less plausible ones).
    """
    walker = Walker(graph, simple, stroke_width)
    nodes = sorted(ranked)

    def run(ranks: tuple[int, ...]) -> tuple[list, list]:
        return walker.traverse({n: ranked[n][r] for n, r in zip(nodes, ranks)})

    start = tuple(0 for _ in nodes)
    best_ranks, (best_strokes, best_closed) = start, run(start)
    tried = 1
    if search and len(best_strokes) > 1 and nodes:
        best_key = (len(best_strokes), 0.0)
        heap = [(0.0, start, 0)]
        seen = {start}
        while heap and tried < MAX_TRAVERSALS:
            cost, ranks, last = heapq.heappop(heap)
            if ranks != start:
                strokes, closed = run(ranks)
                tried += 1
                key = (len(strokes), cost)
                if key < best_key:
                    best_key, best_ranks, best_strokes, best_closed = key, ranks, strokes, closed
                if len(strokes) == 1:
                    break
            # Children change one decision at or after the last changed one: each
            # assignment is generated once, in order of increasing total cost.
            for j in range(last, len(nodes)):
                if ranks[j] + 1 < len(ranked[nodes[j]]):
                    child = ranks[:j] + (ranks[j] + 1,) + ranks[j + 1:]
                    if child not in seen:
                        seen.add(child)
                        delta = costs[nodes[j]][ranks[j] + 1] - costs[nodes[j]][ranks[j]]
                        heapq.heappush(heap, (cost + delta, child, j))
    ordering = Ordering(tuple(tuple(s) for s in best_strokes), tuple(best_closed),
                        tuple(ranked[n][r] for n, r in zip(nodes, best_ranks)))
    return ordering, tried
