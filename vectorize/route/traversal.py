"""Graph ordering (paper 3.3.2): walk the simplified graph into strokes, in drawing order.

The walk starts at an end of the drawing and follows branches; at a degree-4 node it
leaves by the branch the chosen pairing assigns, at a Y-junction it goes down the foot
and back, at other nodes it goes as straight as it can. This is the multi-stroke mode's
walk; a single line is routed by `vectorize.route.route_inspection`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import Simplified, Slot, directions, slot_direction, slot_points, slots
from vectorize.junctions.intersections import Pairing

@dataclass(frozen=True)
class Pass:
    """One traversal of a branch: branch id and the end it starts from ("a" or "b")."""

    branch: int
    start: str

    @property
    def end(self) -> str:
        """The end the pass arrives at ("a" or "b")."""
        return "b" if self.start == "a" else "a"


@dataclass(frozen=True)
class Ordering:
    """Strokes as sequences of branch passes; `choice` is the pairing used per crossing;
    `odd_nodes`: odd-degree nodes route inspection paired or left as ends (single-line mode);
    `undecided`: crossings the single line left undecided (its walk may turn there any way)."""

    strokes: tuple[tuple[Pass, ...], ...]
    closed: tuple[bool, ...]
    choice: tuple
    odd_nodes: int = 0
    undecided: tuple = ()


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
                result.append((node, self._t_stem(node)))
        return result

    def _t_stem(self, node: int) -> int:
        """The slot of a T-junction's line that ends there: outside its smoothest pair."""
        d = self.dirs[node]
        pairs = [(float(np.dot(d[i], d[j])), k) for i, j, k in ((0, 1, 2), (0, 2, 1), (1, 2, 0))]
        return min(pairs)[1]

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
        if node in self.simple.t_ends and entry == self._t_stem(node):
            # A line ending on another ends its stroke there, whichever end the walk began at.
            return None
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
                        path = [Pass(p.branch, p.end) for p in reversed(back)] + path
                strokes.append(path)
                closed.append(is_loop)
        return strokes, closed


def order_strokes(graph: MedialGraph, simple: Simplified, ranked: dict[int, tuple[Pairing, ...]],
                  costs: dict[int, tuple[float, ...]], *, stroke_width: float) -> tuple[Ordering, int]:
    """Traverse with the preferred pairings (multi-stroke mode; single-line drawings are
    routed by `vectorize.route.route_inspection`). Returns the ordering and traversals tried (1).

    ranked[node]: the pairings of a degree-4 node, preferred first; costs[node]: the cost of
    choosing each (unused here, kept for a common signature with the single-line search).
    """
    walker = Walker(graph, simple, stroke_width)
    nodes = sorted(ranked)
    choice = {n: ranked[n][0] for n in nodes}
    strokes, closed = walker.traverse(choice)
    ordering = Ordering(tuple(tuple(p) for p in strokes), tuple(closed), tuple(choice[n] for n in nodes))
    return ordering, 1


def turn_backs(graph: MedialGraph, passes, nodes, reach: float) -> dict[int, int]:
    """Where a stroke turns back at one of `nodes`: {i: node} for the passes i, i + 1 that
    meet at that node and leave it on the same side (their tangents `reach` px beyond the ink
    the node's passes share, less than 90 degrees apart). At a crossing or touch both passes
    usually run on through; a pairing that sends the pen back the way it came (along a band
    of ink two passes share) makes the node a cusp of the line. Measured close to the node
    (not as far as `directions` looks): two branches that share a band and part at its end
    turn back, wherever they go further on."""
    result: dict[int, int] = {}
    for i in range(len(passes) - 1):
        step, after = passes[i], passes[i + 1]
        branch = graph.branches[step.branch]
        node = branch.node(step.end)
        arrive, leave = (step.branch, step.end), (after.branch, after.start)
        if node not in nodes or arrive == leave or step.branch == after.branch:
            continue  # the same branch back is a retrace, handled as one
        out = reach + graph.spans.get(node, 0.0)
        if float(slot_direction(graph, arrive, out) @ slot_direction(graph, leave, out)) > 0.0:
            result[i] = node
    return result


def _shared_points(graph: MedialGraph, one: Slot, two: Slot) -> int:
    """How many points two branch ends at one node have in common from the node on (a merged
    node's branches on one side share the half of the old joining branch they lead along)."""
    p, q = slot_points(graph, one), slot_points(graph, two)
    n = min(len(p), len(q))
    same = np.all(p[:n] == q[:n], axis=1)
    return int(n if same.all() else np.argmin(same))


def half_turns(graph: MedialGraph, passes) -> dict[int, int]:
    """Where a stroke turns back within one half of a merged node's shared ink and need not go
    to the node: {i: points} for passes i, i + 1 that meet at a merged node (`graph.spans`) by
    two branches sharing that half (its first `points` + 1 points, node included), to be cut
    off both passes so that the line turns where the two branches part (the old junction).

    A merged node stands for a band of ink two passes share between two junctions, and a
    pass through it runs the band's length. A pass that turns back within one half (a d's
    stem drawn down, then up to where the connecting stroke met the bowl's top) only goes
    down the band and up the same points again. The band must still be drawn: a half no
    pass runs through keeps its first turn to the node.
    """
    ends = []  # (i, node, half arriving, half leaving, points shared) per turn at a merged node
    for i in range(len(passes) - 1):
        step, after = passes[i], passes[i + 1]
        node = graph.branches[step.branch].node(step.end)
        if graph.spans.get(node, 0.0) <= 0.0:
            continue
        arrive, leave = (step.branch, step.end), (after.branch, after.start)
        if arrive == leave:
            continue  # the same branch end back: a retrace to the node, drawn as one
        shared = _shared_points(graph, arrive, leave)
        ends.append((i, node, tuple(slot_points(graph, arrive)[1]), tuple(slot_points(graph, leave)[1]), shared))
    through = {(node, half) for _, node, h_in, h_out, _ in ends if h_in != h_out for half in (h_in, h_out)}
    result, drawn = {}, set(through)
    for i, node, h_in, h_out, shared in ends:
        if h_in != h_out or shared < 2:
            continue
        if (node, h_in) in drawn:
            result[i] = shared - 1
        drawn.add((node, h_in))
    return result
