"""Pen gaps in single-line mode: bridge the pieces of a broken line, keep the largest.

A line drawn in one stroke still breaks into pieces on paper: the pen skips, a faint stretch
falls under the threshold, the scan loses a pixel column. The paper's method would keep one
piece and lose the rest of the drawing. Here two free ends of different pieces are joined
by a straight branch when they are close (a few stroke widths) and each points at the
other, as the two sides of a gap do; ends that merely lie near each other (a line ending
beside another) do not point at each other and stay apart.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vectorize.graph import Branch, MedialGraph
from vectorize.simplify import slot_direction, slots

BRIDGE_WIDTHS = 4.0  # longest gap bridged, in stroke widths (centre to centre of the caps)
BRIDGE_ANGLE = math.radians(40.0)  # largest angle between an end's direction and the gap
DIRECTION_REACH = 3.0  # an end's direction: from this many stroke widths inside it


def components(graph: MedialGraph) -> dict[int, int]:
    """Node -> index of its connected piece."""
    nodes = list(graph.incident)
    index = {n: i for i, n in enumerate(nodes)}
    ends = np.array([(index[b.a], index[b.b]) for b in graph.branches.values()], dtype=np.int64).reshape(-1, 2)
    links = coo_matrix((np.ones(len(ends)), (ends[:, 0], ends[:, 1])), shape=(len(nodes), len(nodes)))
    _, labels = connected_components(links, directed=False)
    return dict(zip(nodes, labels.tolist()))


def end_direction(graph: MedialGraph, node: int, stroke_width: float) -> np.ndarray:
    """Unit vector (2,) along which the line leaves at free end `node`: the reverse of the
    branch's direction into the ink, `DIRECTION_REACH` widths deep."""
    return -slot_direction(graph, slots(graph, node)[0], DIRECTION_REACH * stroke_width)


def bridge_gaps(graph: MedialGraph, *, stroke_width: float, made: list | None = None) -> int:
    """Join free ends of different pieces across pen gaps, in place; returns the bridges made.

    Pairs are taken cheapest first (gap length in widths plus the two ends' angles off the
    gap, in radians). Ends of different pieces are always joined; ends of one piece only
    while more than two free ends are left. made: a list that receives each bridge's two
    ends, ((x, y), (x, y)) px (the page shows them).
    """
    ends = [n for n, incident in graph.incident.items() if len(incident) == 1]
    if len(ends) < 2:
        return 0
    piece = components(graph)
    reach = BRIDGE_WIDTHS * stroke_width
    position = {n: graph.positions[n] for n in ends}
    heading = {n: end_direction(graph, n, stroke_width) for n in ends}
    pairs = []
    for i, a in enumerate(ends):
        for b in ends[i + 1:]:
            gap = position[b] - position[a]
            length = float(np.linalg.norm(gap))
            if length > reach or length == 0.0:
                continue
            across = gap / length
            off_a = math.acos(float(np.clip(heading[a] @ across, -1.0, 1.0)))
            off_b = math.acos(float(np.clip(heading[b] @ -across, -1.0, 1.0)))
            if off_a <= BRIDGE_ANGLE and off_b <= BRIDGE_ANGLE:
                pairs.append((length / stroke_width + off_a + off_b, a, b, length))
    root = {p: p for p in set(piece.values())}

    def find(p: int) -> int:
        while root[p] != p:
            root[p] = root[root[p]]
            p = root[p]
        return p

    used: set[int] = set()
    bridges = 0
    open_ends = len(ends)
    for _, a, b, length in sorted(pairs):
        if a in used or b in used:
            continue
        # Within one piece a bridge closes a loop: only while the line has more free ends
        # than a single line can have (two), so a nearly closed "C" stays open.
        if find(piece[a]) == find(piece[b]) and open_ends < 4:
            continue
        open_ends -= 2
        root[find(piece[a])] = find(piece[b])
        used.update((a, b))
        count = max(2, int(math.ceil(length)) + 1)
        points = np.linspace(position[a], position[b], count)
        radii = np.linspace(graph.radii[a], graph.radii[b], count)
        graph.add_branch(Branch(a, b, points, radii, np.ones(count - 1)))
        if made is not None:
            made.append((tuple(map(float, position[a])), tuple(map(float, position[b]))))
        bridges += 1
    if bridges:
        graph.dissolve_degree_two()
    return bridges


def keep_largest_piece(graph: MedialGraph) -> int:
    """Remove every piece but the one with the most centre line, in place; returns how many
    pieces went."""
    piece = components(graph)
    if len(set(piece.values())) < 2:
        return 0
    length: dict[int, float] = {}
    for branch in graph.branches.values():
        length[piece[branch.a]] = length.get(piece[branch.a], 0.0) + branch.length
    keep = max(length, key=length.get) if length else piece[next(iter(piece))]
    for node in [n for n, p in piece.items() if p != keep]:
        graph.remove_node(node)
    return len(set(piece.values())) - 1
