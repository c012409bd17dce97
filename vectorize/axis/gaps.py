"""Pen gaps in single-line mode: bridge the pieces of a broken line, keep the largest.

A line drawn in one stroke still breaks into pieces on paper: the pen skips, a faint stretch
falls under the threshold, the scan loses a pixel column. The paper's method would keep one
piece and lose the rest of the drawing. Here two free ends of different pieces are joined
by a straight branch when they are close (a few stroke widths) and each points at the
other, as the two sides of a gap do; ends that merely lie near each other (a line ending
beside another) do not point at each other and stay apart. A gap can also cut a line off
where it meets another (the foot of a T, a stem below a corner): the far side of such a gap
is the middle of a line, not an end, so a free end left in a separate piece is joined to
the nearest centre line of another piece it points at, making the junction the ink had.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vectorize.axis.graph import Branch, MedialGraph
from vectorize.axis.simplify import slot_direction, slots

BRIDGE_WIDTHS = 4.0  # longest gap bridged, in stroke widths (centre to centre of the caps)
# plus this many px: the threshold eats up to a pixel of each anti-aliased cap, which in
# widths matters only for thin lines (at 2-3 px a 1.5-width gap would otherwise be missed)
BRIDGE_SLACK = 2.0
BRIDGE_ANGLE = math.radians(40.0)  # largest angle between an end's direction and the gap
DIRECTION_REACH = 3.0  # an end's direction: from this many stroke widths inside it
# A free end is bridged to the middle of another piece's line only where that line turns (a
# corner or a junction: what is left where a gap cut a line off), never to a straight side.
CORNER_TURN = math.radians(30.0)  # least turn of the line there (legs at most 150 degrees apart)
CORNER_CLEAR = math.radians(60.0)  # least angle between the gap and either leg: the end faces the outside
CORNER_LEG = 1.5  # legs measured this many stroke widths out along the line


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


def bridge_gaps(graph: MedialGraph, *, stroke_width: float, made: list | None = None, refuse=None) -> int:
    """Join free ends of different pieces across pen gaps, in place; returns the bridges made.

    Pairs are taken cheapest first (gap length in widths plus the two ends' angles off the
    gap, in radians). Ends of different pieces are always joined; ends of one piece only
    while more than two free ends are left. made: a list that receives each bridge's two
    ends, ((x, y), (x, y)) px (the page shows them). refuse: None or a callable
    refuse(a, b) -> bool asked before each bridge is made, with its two ends (2,) px: True
    leaves that gap open (a user said the two sides are separate strokes); the ends may
    still be bridged elsewhere.
    """
    ends = [n for n, incident in graph.incident.items() if len(incident) == 1]
    if len(ends) < 2:
        return 0
    piece = components(graph)
    reach = BRIDGE_WIDTHS * stroke_width + BRIDGE_SLACK
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
    find = partial(_find, root)
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
        if refuse is not None and refuse(graph.positions[a], graph.positions[b]):
            continue
        open_ends -= 2
        root[find(piece[a])] = find(piece[b])
        used.update((a, b))
        _add_bridge(graph, a, b, length, made)
        bridges += 1
    bridges += _bridge_to_lines(graph, stroke_width, heading, piece, root, made, refuse)
    if bridges:
        graph.dissolve_degree_two()
    return bridges


def _bridge_to_lines(graph: MedialGraph, stroke_width: float, heading: dict, piece: dict, root: dict,
                     made: list | None = None, refuse=None) -> int:
    """Join free ends of pieces that are still apart to the nearest centre-line point of
    another piece that each points at (within `BRIDGE_WIDTHS` and `BRIDGE_ANGLE`) where that
    line turns with its outside to the end (`_faces`), cheapest first, splitting the branch
    there; returns the bridges made.

    Pieces with less centre line than `BRIDGE_WIDTHS` widths (dust, a dot) are not joined.
    piece: node -> piece index; root: the union-find over pieces of the end-to-end bridges;
    made, refuse: as in `bridge_gaps`."""
    find = partial(_find, root)
    reach = BRIDGE_WIDTHS * stroke_width + BRIDGE_SLACK
    length: dict[int, float] = {}
    for branch in graph.branches.values():
        length[find(piece[branch.a])] = length.get(find(piece[branch.a]), 0.0) + branch.length
    if len(length) < 2:
        return 0
    big = {p for p, total in length.items() if total >= BRIDGE_WIDTHS * stroke_width}
    ids = list(graph.branches)
    points = [graph.branches[b].points for b in ids]
    owner = np.concatenate([np.full(len(p), k) for k, p in enumerate(points)])
    where = np.concatenate([np.arange(len(p)) for p in points])
    points_all = np.concatenate(points)
    groups = np.array([find(piece[graph.branches[b].a]) for b in ids])[owner]
    candidates = []
    for end, direction in heading.items():
        if end not in graph.incident or len(graph.incident[end]) != 1 or find(piece[end]) not in big:
            continue
        gap = points_all - graph.positions[end]
        dist = np.linalg.norm(gap, axis=1)
        cos_off = (gap @ direction) / np.maximum(dist, 1e-9)
        ok = (groups != find(piece[end])) & (dist <= reach) & (dist > 0) & (cos_off >= math.cos(BRIDGE_ANGLE))
        ok &= np.isin(groups, list(big))
        cost = dist / stroke_width + np.arccos(np.clip(cos_off, -1.0, 1.0))
        for k in np.flatnonzero(ok)[np.argsort(cost[ok], kind="stable")]:
            if _faces(graph, ids[owner[k]], int(where[k]), -gap[k] / dist[k], stroke_width):
                candidates.append((float(cost[k]), end, ids[owner[k]], int(where[k]), float(dist[k])))
                break
    bridges = 0
    split: set[int] = set()
    for _, end, bid, index, gap in sorted(candidates):
        if bid in split:
            continue  # its points now lie on new branches; a T-gap rarely has two candidates
        target_piece = piece[graph.branches[bid].a]
        if find(piece[end]) == find(target_piece):
            continue  # already joined by a cheaper bridge
        if refuse is not None and refuse(graph.positions[end], graph.branches[bid].points[index]):
            continue
        target = graph.split_branch(bid, index)
        split.add(bid)
        piece[target] = target_piece
        root[find(piece[end])] = find(target_piece)
        _add_bridge(graph, end, target, gap, made)
        bridges += 1
    return bridges


def _find(root: dict, p: int) -> int:
    """The representative of piece `p` in the union-find `root` (piece -> parent), halving
    the path on the way."""
    while root[p] != p:
        root[p] = root[root[p]]
        p = root[p]
    return p


def _add_bridge(graph: MedialGraph, a: int, b: int, length: float, made: list | None) -> None:
    """A straight branch from node a to node b (`length` px apart) with the radii running
    from one end's to the other's; its two ends go to `made` (see `bridge_gaps`)."""
    count = max(2, int(math.ceil(length)) + 1)
    points = np.linspace(graph.positions[a], graph.positions[b], count)
    radii = np.linspace(graph.radii[a], graph.radii[b], count)
    graph.add_branch(Branch(a, b, points, radii, np.ones(count - 1)))
    if made is not None:
        made.append((tuple(map(float, graph.positions[a])), tuple(map(float, graph.positions[b]))))


def _faces(graph: MedialGraph, bid: int, index: int, toward: np.ndarray, stroke_width: float) -> bool:
    """Whether the line through point `index` of branch `bid` turns there (a corner, or a
    junction node) with its outside toward the unit vector `toward` (module constants)."""
    branch = graph.branches[bid]
    reach = CORNER_LEG * stroke_width
    node = branch.a if index == 0 else (branch.b if index == len(branch.points) - 1 else None)
    if node is not None:
        if graph.degree(node) < 3:
            return False  # a free end: bridged end to end, or not at all
        legs = np.array([slot_direction(graph, slot, reach) for slot in slots(graph, node)])
    else:
        arc = branch.arc
        point = branch.points[index]
        legs = []
        for target in (arc[index] - reach, arc[index] + reach):
            at = np.array([np.interp(target, arc, branch.points[:, 0]), np.interp(target, arc, branch.points[:, 1])])
            legs.append((at - point) / max(float(np.linalg.norm(at - point)), 1e-9))
        legs = np.array(legs)
        if float(legs[0] @ legs[1]) < math.cos(math.pi - CORNER_TURN):
            return False  # a straight side: a line stopped beside it, not cut off from it
    return bool(np.all(legs @ toward <= math.cos(CORNER_CLEAR)))


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
