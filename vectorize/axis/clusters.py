"""Three passes through one point: a cluster of junctions read as one node.

Where three lines cross at one spot the medial axis does not show one node of degree 6
but a small tree of degree-3 junctions (typically four, joined by branches shorter than a
stroke width) with six branch feet leaving it. Merging those junctions in pairs, as
crossings are merged, cannot represent three passes (the paper's Fig. 12 failure).
Instead the whole cluster becomes one node, and its six feet are paired by good
continuation: the three pairs that together bend least, so that each pass goes straight
through.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vectorize.axis.graph import Branch, MedialGraph
from vectorize.axis.simplify import directions

# Junctions joined by branches shorter than this many stroke widths are one cluster; so are
# junctions whose maximal discs overlap (the branch is shorter than their radii's sum): the
# ink they sit in is one blob, however thin the drawing's lines are elsewhere.
CLUSTER_REACH = 1.5
# Each pass through a triple point bends by less than this (degrees from straight).
MAX_BEND = 40.0

Pairs = tuple[tuple[int, int], ...]


def matchings(items: list[int]):
    """Every way to split `items` (even count) into pairs."""
    if not items:
        yield ()
        return
    first = items[0]
    for k in range(1, len(items)):
        for rest in matchings(items[1:k] + items[k + 1:]):
            yield ((first, items[k]),) + rest


def straightest_pairs(dirs: np.ndarray) -> tuple[Pairs, float]:
    """The pairing of slots whose passes bend least, and its largest bend (degrees).

    dirs: (2k, 2) unit tangents leaving the node. A pass from slot a to slot b bends by
    the angle between -dirs[a] and dirs[b].
    """
    best, best_cost = (), np.inf
    for pairs in matchings(list(range(len(dirs)))):
        cost = sum(1.0 + float(np.dot(dirs[a], dirs[b])) for a, b in pairs)
        if cost < best_cost:
            best, best_cost = pairs, cost
    return best, max(pass_bends(dirs, best))


def pass_bends(dirs: np.ndarray, pairs) -> list[float]:
    """Degrees each pass of `pairs` (slot pairs) turns by at the node (0 = straight through);
    dirs: (D, 2) unit tangents leaving it."""
    d = np.asarray(dirs, dtype=float)
    return [float(np.degrees(np.arccos(np.clip(-np.dot(d[a], d[b]), -1.0, 1.0)))) for a, b in pairs]


def merge_cluster(graph: MedialGraph, nodes: list[int], inner: list[int], centre: np.ndarray | None = None,
                  renamed: dict | None = None) -> int:
    """Replace the cluster's junctions and inner branches by one node at `centre` (default:
    the junctions' centre); `renamed` (if given) gets old branch id -> new for the branches
    that now end at the node."""
    if centre is None:
        centre = np.mean([graph.positions[n] for n in nodes], axis=0)
    node = graph.add_node(centre, max(graph.radii[n] for n in nodes))
    graph.spans[node] = float(max(np.linalg.norm(graph.positions[n] - centre) for n in nodes))
    for bid in inner:
        graph.remove_branch(bid)
    members = set(nodes)
    for bid in sorted({b for n in nodes for b in graph.incident[n]}):
        branch = graph.remove_branch(bid)

        def lead(end_node: int) -> tuple[np.ndarray, np.ndarray]:
            # A straight run from the new node to the old junction, then the branch.
            count = max(2, int(np.ceil(np.linalg.norm(graph.positions[end_node] - centre))) + 1)
            pts = np.linspace(centre, graph.positions[end_node], count)
            return pts, np.full(count, graph.radii[end_node])

        points, radii, sins = branch.points, branch.radii, branch.sins
        a, b = branch.a, branch.b
        if a in members:
            pts, rad = lead(a)
            points, radii = np.vstack([pts[:-1], points]), np.concatenate([rad[:-1], radii])
            sins = np.concatenate([np.ones(len(pts) - 1), sins])
            a = node
        if b in members:
            pts, rad = lead(b)
            points, radii = np.vstack([points, pts[::-1][1:]]), np.concatenate([radii, rad[::-1][1:]])
            sins = np.concatenate([sins, np.ones(len(pts) - 1)])
            b = node
        new = graph.add_branch(Branch(a, b, points, radii, sins))
        if renamed is not None:
            renamed[bid] = new
    for n in nodes:
        del graph.incident[n], graph.positions[n], graph.radii[n]
    return node


def linked_groups(graph: MedialGraph, junctions: list[int], links: list[int]) -> list[list[int]]:
    """The junctions (node ids) in groups joined by the branches `links` (ids of branches
    between two of them), each group in `junctions` order."""
    index = {n: i for i, n in enumerate(junctions)}
    rows = [index[graph.branches[b].a] for b in links]
    cols = [index[graph.branches[b].b] for b in links]
    matrix = coo_matrix((np.ones(len(links)), (rows, cols)), shape=(len(junctions), len(junctions)))
    _, label = connected_components(matrix, directed=False)
    groups: dict[int, list[int]] = {}
    for n in junctions:
        groups.setdefault(int(label[index[n]]), []).append(n)
    return list(groups.values())


def merge_triple_points(graph: MedialGraph, *, stroke_width: float, may_merge=None) -> dict[int, Pairs]:
    """Find clusters of junctions where three passes cross and merge each into one node, in
    place. Returns node -> its three slot pairs (the passes straight through it); pair again
    after later merges, which renumber a node's slots.

    may_merge(branch) -> False keeps a cluster apart (a user's split edit).
    """
    junctions = [n for n in graph.incident if graph.degree(n) == 3]
    known = set(junctions)
    short = [bid for bid, b in graph.branches.items()
             if b.a != b.b and b.a in known and b.b in known
             and b.length < max(CLUSTER_REACH * stroke_width, graph.radii[b.a] + graph.radii[b.b])]
    if not short:
        return {}
    result = {}
    for members in linked_groups(graph, junctions, short):
        if len(members) != 4:
            continue
        inside = set(members)
        # (Branches of clusters merged before are gone: their ids are no longer in the graph.)
        inner = [b for b in short if b in graph.branches and graph.branches[b].a in inside]
        # A tree of four junctions: six feet leave it.
        if len(inner) != 3 or (may_merge is not None and not all(may_merge(graph.branches[b]) for b in inner)):
            continue
        trial = graph.copy()
        node = merge_cluster(trial, sorted(members), inner)
        pairs, bend = straightest_pairs(directions(trial, node, 2.5 * stroke_width))
        if bend > MAX_BEND:
            continue
        node = merge_cluster(graph, sorted(members), inner)
        result[node] = straightest_pairs(directions(graph, node, 2.5 * stroke_width))[0]
    return result

