"""The medial-axis graph: junction and end nodes joined by branches (polylines with radii).

Chains of degree-2 Voronoi vertices are collapsed into branches as soon as the axis is
built, so every later stage works on a few hundred nodes and branches, not 20k vertices.
The graph is mutable while the stages simplify it; stages hand on finished results only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from vectorize.stroke import edge_lengths


@dataclass
class Branch:
    """A chain of medial-axis points from node `a` to node `b` (both ends included).

    points: (M, 2) x, y px; radii: (M,) distance to the outline px; sins: (M-1,) sine of
    the object angle per edge (1 on a true centre line, small on noise spurs).
    """

    a: int
    b: int
    points: np.ndarray
    radii: np.ndarray
    sins: np.ndarray

    # Cached: pruning asks every leaf for these on every round, and a branch's arrays are
    # never changed once made (stages replace branches instead).
    def node(self, end: str) -> int:
        """The node at end "a" or "b"."""
        return self.a if end == "a" else self.b

    @cached_property
    def edge_lengths(self) -> np.ndarray:
        """(M-1,) px: the length of each edge (read only: shared with derived branches)."""
        return edge_lengths(self.points)

    @cached_property
    def arc(self) -> np.ndarray:
        """(M,) px: arc length at each point, from `a`."""
        return np.concatenate([[0.0], np.cumsum(self.edge_lengths)])

    @cached_property
    def arc_back(self) -> np.ndarray:
        """(M,) px: arc length at each point of the branch read from `b` (points[::-1])."""
        return np.concatenate([[0.0], np.cumsum(self.edge_lengths[::-1])])

    @cached_property
    def length(self) -> float:
        return float(self.edge_lengths.sum())

    @cached_property
    def significance(self) -> float:
        """Length-weighted mean sine of the object angle (vanishing-angle measure)."""
        lengths = self.edge_lengths
        total = lengths.sum()
        return float((lengths * self.sins).sum() / total) if total > 0 else 0.0

    def other(self, node: int) -> int:
        return self.b if node == self.a else self.a

    def oriented_from(self, node: int) -> "Branch":
        """This branch read starting at `node`."""
        if node == self.a:
            return self
        reverse = Branch(self.b, self.a, self.points[::-1], self.radii[::-1], self.sins[::-1])
        if "edge_lengths" in self.__dict__:
            # The same edges the other way (|-d| = |d| exactly); sums are taken afresh,
            # in the new order, as they always were.
            reverse.__dict__["edge_lengths"] = self.__dict__["edge_lengths"][::-1]
        return reverse


# `measure_short` measures branches of up to this many points together.
SHORT = 8


def measure_short(branches: list[Branch]) -> None:
    """Fill in `length` and `significance` of the branches with at most `SHORT` points, all
    at once (pruning asks for them of every leaf, and most leaves are one or two Voronoi
    edges: one small array each cost more than the arithmetic).

    The numbers are exactly the properties' own: numpy sums fewer than 8 numbers one after
    the other (pairwise blocks start at 8), and so do the sums here.
    """
    short = [b for b in branches
             if len(b.points) <= SHORT and len(b.sins) == len(b.points) - 1 and "length" not in b.__dict__]
    if not short:
        return
    counts = np.array([len(b.points) for b in short])
    # Edges across two branches' arrays are computed too and masked out; the 0 appended
    # makes every index valid.
    lengths = np.append(edge_lengths(np.concatenate([b.points for b in short])), 0.0)
    sins = np.append(np.concatenate([b.sins for b in short]), 0.0)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    column = np.arange(SHORT - 1)
    mask = column[None, :] < (counts - 1)[:, None]
    edge_at = np.where(mask, starts[:, None] + column[None, :], -1)
    sin_at = np.where(mask, (starts - np.arange(len(short)))[:, None] + column[None, :], -1)
    edges = np.where(mask, lengths[edge_at], 0.0)
    weighted = np.where(mask, edges * sins[sin_at], 0.0)

    def sums(values: np.ndarray) -> np.ndarray:
        total = values[:, 0].copy()
        for k in range(1, values.shape[1]):
            total += values[:, k]  # + 0.0 past a branch's last edge: exact
        return total

    total, moment = sums(edges), sums(weighted)
    for branch, length, weight in zip(short, total.tolist(), moment.tolist()):
        branch.__dict__["length"] = length
        branch.__dict__["significance"] = weight / length if length > 0 else 0.0


class _Chain:
    """Branches joined end to end, from node `a` to node `b`, not yet made into one
    (`MedialGraph.dissolve_degree_two` joins whole runs of degree-2 nodes at once).

    A leaf holds a branch; a join holds two chains, the second without its first point (the
    node they share: the point joining the branches one by one would have dropped). `back`:
    read the whole backwards. Joining and reversing cost the same however long the chain.
    """

    __slots__ = ("a", "b", "part", "back")

    def __init__(self, a: int, b: int, part: "Branch | tuple[_Chain, _Chain]", back: bool = False) -> None:
        self.a, self.b, self.part, self.back = a, b, part, back

    def oriented_from(self, node: int) -> "_Chain":
        return self if node == self.a else _Chain(self.b, self.a, self.part, not self.back)

    def joined(self, after: "_Chain") -> "_Chain":
        """This chain, then `after` without its first point (self.b is after.a)."""
        return _Chain(self.a, after.b, (self, after))

    def parts(self) -> list[tuple[Branch, bool, bool, bool]]:
        """(branch, read backwards, drop its first point, drop its last point) from a to b."""
        parts = []
        stack = [(self, False, False, False)]  # chains still to read, the next on top
        while stack:
            chain, flip, head, tail = stack.pop()
            back = chain.back != flip
            if isinstance(chain.part, Branch):
                parts.append((chain.part, back, head, tail))
                continue
            first, second = chain.part
            if back:  # second read backwards (its dropped first point now last), then first
                stack += [(first, True, False, tail), (second, True, head, True)]
            else:
                stack += [(second, False, True, tail), (first, False, head, False)]
        return parts

    def branch(self) -> Branch:
        """The joined branch."""
        parts = self.parts()
        points, radii, sins, edges = [], [], [], []
        for branch, back, head, tail in parts:
            step = -1 if back else 1
            cut = slice(1 if head else None, -1 if tail else None)
            points.append(branch.points[::step][cut])
            radii.append(branch.radii[::step][cut])
            sins.append(branch.sins[::step])
            edges.append(branch.__dict__.get("edge_lengths"))
        joined = Branch(self.a, self.b, np.concatenate(points), np.concatenate(radii), np.concatenate(sins))
        # Known edge lengths carry over where each joint's two points are one (they always
        # are): the joined branch then measures itself without going over every point again.
        if all(e is not None for e in edges) and all(
                np.array_equal(_end(p1, True), _end(p2, False)) for p1, p2 in zip(parts, parts[1:])):
            joined.__dict__["edge_lengths"] = np.concatenate([e[::-1] if p[1] else e for e, p in zip(edges, parts)])
        return joined


def _end(part: tuple[Branch, bool, bool, bool], last: bool) -> np.ndarray:
    """The first or last point of a chain's part, in the chain's reading, dropped or not."""
    branch, back, _, _ = part
    return branch.points[0 if back == last else -1]


_NO_POINTS = np.zeros(0)


@dataclass
class MedialGraph:
    """Nodes (positions, radii) and branches; `incident[n]` lists the branch ids at node n
    (a loop branch from n to n is listed twice). `spans[n]`: for a node merged from two
    junctions, half the length of the branch that joined them (its ink is shared by both
    strokes, so their directions only show beyond it)."""

    positions: dict[int, np.ndarray] = field(default_factory=dict)
    radii: dict[int, float] = field(default_factory=dict)
    branches: dict[int, Branch] = field(default_factory=dict)
    incident: dict[int, list[int]] = field(default_factory=dict)
    spans: dict[int, float] = field(default_factory=dict)
    _next_node: int = 0
    _next_branch: int = 0

    def add_node(self, position: np.ndarray, radius: float) -> int:
        node = self._next_node
        self._next_node += 1
        self.positions[node] = np.asarray(position, dtype=float)
        self.radii[node] = float(radius)
        self.incident[node] = []
        return node

    def add_branch(self, branch: Branch) -> int:
        bid = self._next_branch
        self._next_branch += 1
        self.branches[bid] = branch
        self.incident[branch.a].append(bid)
        self.incident[branch.b].append(bid)
        return bid

    def remove_branch(self, bid: int) -> Branch:
        branch = self.branches.pop(bid)
        self.incident[branch.a].remove(bid)
        self.incident[branch.b].remove(bid)
        return branch

    def remove_node(self, node: int) -> None:
        for bid in list(self.incident[node]):
            if bid in self.branches:
                self.remove_branch(bid)
        del self.incident[node], self.positions[node], self.radii[node]

    def split_branch(self, bid: int, index: int) -> int:
        """Cut branch `bid` at its point `index` into two branches meeting at a new node
        (an end node when `index` is the first or last point); returns that node."""
        branch = self.branches[bid]
        if index <= 0:
            return branch.a
        if index >= len(branch.points) - 1:
            return branch.b
        self.remove_branch(bid)
        node = self.add_node(branch.points[index], float(branch.radii[index]))
        self.add_branch(Branch(branch.a, node, branch.points[:index + 1], branch.radii[:index + 1],
                               branch.sins[:index]))
        self.add_branch(Branch(node, branch.b, branch.points[index:], branch.radii[index:], branch.sins[index:]))
        return node

    def degree(self, node: int) -> int:
        return len(self.incident[node])

    def nodes_of_degree(self, degree: int) -> list[int]:
        return [n for n, inc in self.incident.items() if len(inc) == degree]

    def dissolve_degree_two(self) -> None:
        """Join the two branches at every degree-2 node into one (loops stay as they are).

        Node by node, in node order, each join a new branch id; the joined arrays are only
        made once a run of joins is done (a long stroke that lost a spur every few pixels
        would otherwise be copied once per spur).
        """
        chains: dict[int, _Chain] = {}  # joined branch ids whose arrays are not made yet

        def take(bid: int) -> _Chain:
            branch = self.branches.pop(bid)
            self.incident[branch.a].remove(bid)
            self.incident[branch.b].remove(bid)
            return chains.pop(bid, None) or _Chain(branch.a, branch.b, branch)

        for node in [n for n, inc in self.incident.items() if len(inc) == 2]:
            first, second = self.incident[node]
            if first == second:
                continue  # an isolated closed loop through this node: keep the node
            c1 = take(first).oriented_from(node)
            c2 = take(second).oriented_from(node)
            # c1 reversed runs into node, then c2 leaves it.
            joined = c1.oriented_from(c1.b).joined(c2)
            del self.incident[node], self.positions[node], self.radii[node]
            # A placeholder branch keeps the graph's bookkeeping (ids, incidence order) exact.
            chains[self.add_branch(Branch(joined.a, joined.b, _NO_POINTS, _NO_POINTS, _NO_POINTS))] = joined
        for bid, chain in chains.items():
            self.branches[bid] = chain.branch()

    def copy(self) -> "MedialGraph":
        graph = MedialGraph(dict(self.positions), dict(self.radii),
                            {k: _same(b) for k, b in self.branches.items()},
                            {k: list(v) for k, v in self.incident.items()}, dict(self.spans),
                            self._next_node, self._next_branch)
        return graph


def _same(branch: Branch) -> Branch:
    """A copy of `branch` sharing its (never changed) arrays and what it measured of them."""
    copy = Branch(branch.a, branch.b, branch.points, branch.radii, branch.sins)
    copy.__dict__.update((k, v) for k, v in branch.__dict__.items() if k not in ("a", "b", "points", "radii", "sins"))
    return copy
