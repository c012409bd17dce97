"""The medial axis (paper 3.2): Voronoi diagram of the outline samples, inside part, radii."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.ndimage import map_coordinates

from onestroke.errors import VectorizeError
from vectorize.axis.graph import Branch, MedialGraph
from vectorize.axis.voronoi import empty_circle_bound, jittered_delaunay, sides, tile_slabs, voronoi_part
from onestroke.cores import idle_cores
from vectorize.stroke import edge_lengths, lengths

# From this many outline samples on, the Voronoi diagram is computed in tiles, one thread per
# core (qhull lets go of the GIL); below, starting the threads costs more than it saves.
TILED_SAMPLES = 4000
MAX_TILES = 8


def _inside(gray: np.ndarray, level: float, xy: np.ndarray) -> np.ndarray:
    """True where the bilinear gray at x, y is ink (the same field the outline came from)."""
    h, w = gray.shape
    ok = (xy[:, 0] >= 0) & (xy[:, 0] <= w - 1) & (xy[:, 1] >= 0) & (xy[:, 1] <= h - 1)
    values = np.ones(len(xy))
    values[ok] = map_coordinates(gray, [xy[ok, 1], xy[ok, 0]], order=1)
    return ok & (values < level)


def medial_axis(rings: list[np.ndarray], gray: np.ndarray, level: float, *, tiles: int | None = None,
                beside: Callable[[], object] | None = None) -> MedialGraph:
    """Inside Voronoi ridges of the outline samples as a graph of branches.

    A ridge is kept when both its vertices lie inside the ink and its two generating samples
    are not neighbours on one ring (those ridges cut the outline, not the ink's middle).
    Vertices come in the order of their coordinates and ridges in the order of their
    vertices, so the graph does not depend on how the diagram was computed.
    tiles: how many tiles to compute the diagram in, one thread each (1: whole; None: one
    per core from `TILED_SAMPLES` samples on, while the machine has a core to spare); it
    falls back to the whole diagram where the ink's widest part would make the tiles
    overlap too much. beside: work for this thread while qhull works (it holds the GIL, qhull
    does not): with a core to spare, qhull triangulates in another thread meanwhile (tiles:
    one per core but this thread's, each made in a thread of its own); else `beside` is
    done first.
    """
    if not rings:
        raise VectorizeError("the ink has no outline to work from")
    samples = np.vstack(rings)
    if len(samples) < 8:
        raise VectorizeError("the ink is too small to find its centre line")
    # The next sample along each sample's ring (rings close: the last one's is the first).
    sizes = np.array([len(r) for r in rings])
    firsts = np.cumsum(sizes) - sizes
    following = np.arange(1, len(samples) + 1)
    following[firsts + sizes - 1] = firsts
    span = float(np.max(sides(samples))) + 1.0

    def inside_ridges(chosen=None, slab=(-np.inf, np.inf), core=(-np.inf, np.inf), axis=0, delaunay=None):
        """This tile's kept ridges (key pairs, sample pairs) and their vertices' (keys,
        centres, radii); None when an inside vertex of its core does not fit its slab."""
        part = voronoi_part(samples, chosen, span=span, axis=axis, slab=slab, delaunay=delaunay)
        p, q = part.ridge_points[:, 0], part.ridge_points[:, 1]
        keep = (following[p] != q) & (following[q] != p)  # not two neighbours on one ring
        ends = part.ridges[keep]
        inside = np.zeros(len(part.key), dtype=bool)
        asked = np.flatnonzero(np.bincount(ends.ravel(), minlength=len(part.key)))
        if len(asked):
            inside[asked] = _inside(gray, level, part.center[asked])
        keep[keep] = inside[ends[:, 0]] & inside[ends[:, 1]]
        ends = part.ridges[keep]
        mine = (part.center[:, axis] >= core[0]) & (part.center[:, axis] < core[1])
        if (inside & mine & ~part.fits).any():
            return None
        keep[keep] = part.fits[ends[:, 0]] & part.fits[ends[:, 1]]
        ends = part.ridges[keep]
        used = np.bincount(ends.ravel(), minlength=len(part.key)) > 0
        number = np.cumsum(used) - 1
        return (number[ends], part.ridge_points[keep], part.key[used], part.center[used], part.radius[used])

    # Threads only pay with idle cores (on a busy machine they would also add the tiles'
    # overlap).
    cores = idle_cores() if tiles is None or beside is not None else 1
    if tiles is None:
        spare = cores - 1 if beside is not None and cores > 1 else cores
        tiles = min(spare, MAX_TILES) if len(samples) >= TILED_SAMPLES else 1
    slabs = None
    if tiles > 1:
        spacing = max(float(np.max(edge_lengths(np.concatenate([ring, ring[:1]])))) for ring in rings)
        bound = empty_circle_bound(samples, gray, level, spacing)
        # A kept ridge's two circles lie within twice the bound of its midpoint: a tile
        # widened by that finds every ridge whose midpoint is in its core.
        slabs = tile_slabs(samples, 2.0 * bound, tiles) if np.isfinite(bound) else None
    jobs = slabs if slabs is not None else [()]  # () : the whole diagram
    overlap = beside is not None and cores > 1
    if beside is not None and not overlap:
        beside()
    if len(jobs) > 1:  # each tile in a thread of its own
        with ThreadPoolExecutor(max_workers=len(jobs)) as pool:
            running = [pool.submit(inside_ridges, *job) for job in jobs]
            if overlap:
                beside()
            parts = [job.result() for job in running]
    elif overlap:
        # Only qhull in the other thread: the rest of the diagram's making holds the GIL,
        # as `beside` does, and would wait for it there.
        with ThreadPoolExecutor(max_workers=1) as pool:
            triangulating = pool.submit(jittered_delaunay, samples)
            beside()
            parts = [inside_ridges(delaunay=triangulating.result())]
    else:
        parts = [inside_ridges()]
    if any(part is None for part in parts):  # a tile's inside vertex did not fit its slab
        parts = [inside_ridges()]
    # One vertex per name (a vertex found in two tiles has the same bits in both), in the
    # order of its coordinates (x, then y); ridges in the order of their vertices.
    offsets = np.cumsum([0] + [len(part[2]) for part in parts[:-1]])
    ridges = np.concatenate([part[0] + offset for part, offset in zip(parts, offsets)])
    ridge_points, keys, centers, radii = (np.concatenate(column) for column in list(zip(*parts))[1:])
    if len(ridges) == 0:
        raise VectorizeError("no centre line found inside the ink")
    order = np.argsort(keys)
    new = np.concatenate([[True], keys[order[1:]] != keys[order[:-1]]])
    once = order[new]
    place = np.lexsort((keys[once], centers[once, 1], centers[once, 0]))
    rank = np.empty(len(once), dtype=np.int64)
    rank[place] = np.arange(len(once))
    vertex_of = np.empty(len(keys), dtype=np.int64)
    vertex_of[order] = rank[np.cumsum(new) - 1]
    xy, radius = centers[once[place]], radii[once[place]]
    ends = np.sort(vertex_of[ridges], axis=1)
    pair = ends[:, 0] * len(xy) + ends[:, 1]
    order = np.argsort(pair)
    once = order[np.concatenate([[True], pair[order[1:]] != pair[order[:-1]]])]
    edges, ridge_points = ends[once], ridge_points[once]
    # Object angle: half the angle at the ridge midpoint between its two generating samples.
    # (The same numbers as the mean over each edge's two ends, `.sum(1)` of the products and
    # `np.linalg.norm(.., axis=1)`, without numpy's slow reductions over axes of two.)
    mid = (xy[edges[:, 0]] + xy[edges[:, 1]]) / 2.0
    u = samples[ridge_points[:, 0]] - mid
    v = samples[ridge_points[:, 1]] - mid
    cos = (u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1]) / np.maximum(lengths(u) * lengths(v), 1e-12)
    sins = np.sin(np.arccos(np.clip(cos, -1.0, 1.0)) / 2.0)
    return _collapse_chains(xy, radius, edges, sins)


def _collapse_chains(xy: np.ndarray, radius: np.ndarray, edges: np.ndarray, sins: np.ndarray) -> MedialGraph:
    """Build the branch graph: each chain of degree-2 vertices between junctions or ends is
    one branch, read from the end met first in vertex order (then adjacency order); closed
    chains with no junction get a node of their own, in the order of their first edge."""
    n, count = len(xy), len(edges)
    degree = np.bincount(edges.ravel(), minlength=n)
    # Half-edges in CSR order (by source vertex, then edge id): j runs source[j] -> target[j]
    # along edge edge_of[j]; reverse[j] is the same edge the other way.
    order = np.argsort(np.concatenate([edges[:, 0], edges[:, 1]]), kind="stable")
    source = np.concatenate([edges[:, 0], edges[:, 1]])[order]
    target = np.concatenate([edges[:, 1], edges[:, 0]])[order]
    edge_of = np.concatenate([np.arange(count), np.arange(count)])[order]
    start = np.concatenate([[0], np.cumsum(degree)])
    halves = 2 * count
    by_edge = np.argsort(edge_of, kind="stable").reshape(-1, 2)
    reverse = np.empty(halves, dtype=np.int64)
    reverse[by_edge[:, 0]], reverse[by_edge[:, 1]] = by_edge[:, 1], by_edge[:, 0]
    # A chain goes on through a degree-2 vertex by its other half-edge, and stops elsewhere.
    slot = start[target]
    succ = np.where(degree[target] == 2, np.where(slot == reverse, slot + 1, slot), -1)
    pred = np.full(halves, -1, dtype=np.int64)
    going = np.flatnonzero(succ >= 0)
    pred[succ[going]] = going
    # List ranking by pointer jumping: each half-edge's chain start and its rank in the chain.
    index = np.arange(halves)
    head = np.where(pred >= 0, pred, index)
    rank = (pred >= 0).astype(np.int64)
    for _ in range(max(1, int(halves).bit_length())):
        ahead = head[head]
        if np.array_equal(ahead, head):
            break
        rank += rank[head] * (ahead != head)
        head = ahead
    # Half-edges of closed chains never reach a start (a half-edge leaving a node).
    opened = degree[source[head]] != 2
    last = np.flatnonzero(opened & (succ < 0))
    end_of = np.zeros(halves, dtype=np.int64)  # (read for closed chains too, then masked)
    end_of[head[last]] = last
    # Each chain was walked from the end whose half-edge comes first in CSR order.
    walked = opened & (head < reverse[end_of[head]])

    graph = MedialGraph()
    ends = np.flatnonzero(degree != 2)
    node_of = np.full(n, -1, dtype=np.int64)
    end_xy, end_radius = xy[ends], radius[ends].tolist()
    for k, vertex in enumerate(ends.tolist()):
        node_of[vertex] = graph.add_node(end_xy[k], end_radius[k])
    chain = np.flatnonzero(walked)
    chain = chain[np.lexsort((rank[chain], head[chain]))]
    cuts = np.flatnonzero(np.diff(head[chain])) + 1
    firsts = np.concatenate([[0], cuts]) if len(chain) else np.zeros(0, dtype=np.int64)  # no chain: all closed
    # Every chain's vertices in one gather: chain k's path (its first half-edge's source,
    # then each half-edge's target) is path[firsts[k] + k: stops[k] + k + 1]; its branch
    # holds views of the gathered arrays (branches never change their arrays).
    path = np.insert(target[chain], firsts, source[chain[firsts]])
    points, radii, sines = xy[path], radius[path], sins[edge_of[chain]]
    stops = np.append(firsts[1:], len(chain))
    shift = np.arange(len(firsts))
    starts, finals = (firsts + shift).tolist(), (stops + shift).tolist()
    a_nodes, b_nodes = node_of[path[starts]].tolist(), node_of[path[finals]].tolist()
    for lo, hi, first, final, a, b in zip(firsts.tolist(), stops.tolist(), starts, finals, a_nodes, b_nodes):
        graph.add_branch(Branch(a, b, points[first:final + 1], radii[first:final + 1], sines[lo:hi]))
    # What is left are closed chains of degree-2 vertices: each gets a node at the first
    # vertex of its lowest edge and is read from there along that edge.
    seen = np.zeros(count, dtype=bool)
    seen[edge_of[walked]] = True
    succ_l, target_l, edge_l = succ.tolist(), target.tolist(), edge_of.tolist()
    for e in np.flatnonzero(~seen).tolist():
        if seen[e]:
            continue
        vertex = int(edges[e, 0])
        j = int(by_edge[e, 0] if source[by_edge[e, 0]] == vertex else by_edge[e, 1])
        path, path_edges = [vertex], []
        while True:
            path.append(target_l[j])
            path_edges.append(edge_l[j])
            if target_l[j] == vertex:
                break
            j = succ_l[j]
        seen[path_edges] = True
        node = graph.add_node(xy[vertex], radius[vertex])
        graph.add_branch(Branch(node, node, xy[path], radius[path], sins[path_edges]))
    return graph
