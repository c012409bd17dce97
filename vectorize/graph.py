"""The medial-axis graph: junction and end nodes joined by branches (polylines with radii).

Chains of degree-2 Voronoi vertices are collapsed into branches as soon as the axis is
built, so every later stage works on a few hundred nodes and branches, not 20k vertices.
The graph is mutable while the stages simplify it; stages hand on finished results only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np


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

    @property
    def edge_lengths(self) -> np.ndarray:
        return np.linalg.norm(np.diff(self.points, axis=0), axis=1)

    # Cached: pruning asks every leaf for both on every round, and a branch's arrays are
    # never changed once made (stages replace branches instead).
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
        return Branch(self.b, self.a, self.points[::-1], self.radii[::-1], self.sins[::-1])


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
        """Join the two branches at every degree-2 node into one (loops stay as they are)."""
        for node in [n for n, inc in self.incident.items() if len(inc) == 2]:
            first, second = self.incident[node]
            if first == second:
                continue  # an isolated closed loop through this node: keep the node
            b1 = self.remove_branch(first).oriented_from(node)
            b2 = self.remove_branch(second).oriented_from(node)
            # b1 reversed runs into node, then b2 leaves it.
            into = Branch(b1.b, node, b1.points[::-1], b1.radii[::-1], b1.sins[::-1])
            joined = Branch(into.a, b2.b, np.vstack([into.points, b2.points[1:]]),
                            np.concatenate([into.radii, b2.radii[1:]]),
                            np.concatenate([into.sins, b2.sins]))
            del self.incident[node], self.positions[node], self.radii[node]
            self.add_branch(joined)

    def copy(self) -> "MedialGraph":
        graph = MedialGraph(dict(self.positions), dict(self.radii),
                            {k: Branch(b.a, b.b, b.points, b.radii, b.sins) for k, b in self.branches.items()},
                            {k: list(v) for k, v in self.incident.items()}, dict(self.spans),
                            self._next_node, self._next_branch)
        return graph
