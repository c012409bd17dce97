"""The medial axis (paper 3.2): Voronoi diagram of the outline samples, inside part, radii."""

from __future__ import annotations

from itertools import chain

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.spatial import Voronoi

from onestroke.errors import VectorizeError
from vectorize.graph import Branch, MedialGraph


def _inside(gray: np.ndarray, level: float, xy: np.ndarray) -> np.ndarray:
    """True where the bilinear gray at x, y is ink (the same field the outline came from)."""
    h, w = gray.shape
    ok = (xy[:, 0] >= 0) & (xy[:, 0] <= w - 1) & (xy[:, 1] >= 0) & (xy[:, 1] <= h - 1)
    values = np.ones(len(xy))
    values[ok] = map_coordinates(gray, [xy[ok, 1], xy[ok, 0]], order=1)
    return ok & (values < level)


def medial_axis(rings: list[np.ndarray], gray: np.ndarray, level: float) -> MedialGraph:
    """Inside Voronoi ridges of the outline samples as a graph of branches.

    A ridge is kept when both its vertices lie inside the ink and its two generating samples
    are not neighbours on one ring (those ridges cut the outline, not the ink's middle).
    """
    if not rings:
        raise VectorizeError("the ink has no outline to work from")
    samples = np.vstack(rings)
    ring_of = np.repeat(np.arange(len(rings)), [len(r) for r in rings])
    ring_size = np.array([len(r) for r in rings])[ring_of]
    index_in_ring = np.concatenate([np.arange(len(r)) for r in rings])
    if len(samples) < 8:
        raise VectorizeError("the ink is too small to find its centre line")
    voronoi = Voronoi(samples)
    # In the plane every ridge has two vertices (-1: at infinity); flattening the list of
    # pairs costs half of building an array from it.
    ridge_vertices = np.fromiter(chain.from_iterable(voronoi.ridge_vertices), dtype=np.int64,
                                 count=2 * len(voronoi.ridge_vertices)).reshape(-1, 2)
    ridge_points = voronoi.ridge_points
    p, q = ridge_points[:, 0], ridge_points[:, 1]
    gap = np.abs(index_in_ring[p] - index_in_ring[q])
    gap = np.minimum(gap, ring_size[p] - gap)
    neighbours = (ring_of[p] == ring_of[q]) & (gap <= 1)
    finite = (ridge_vertices >= 0).all(axis=1)
    inside_vertex = _inside(gray, level, voronoi.vertices)
    keep = finite & ~neighbours
    keep[keep] &= inside_vertex[ridge_vertices[keep, 0]] & inside_vertex[ridge_vertices[keep, 1]]
    edges = ridge_vertices[keep]
    if len(edges) == 0:
        raise VectorizeError("no centre line found inside the ink")
    # Object angle: half the angle at the ridge midpoint between its two generating samples.
    mid = voronoi.vertices[edges].mean(axis=1)
    u = samples[p[keep]] - mid
    v = samples[q[keep]] - mid
    cos = (u * v).sum(1) / np.maximum(np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-12)
    sins = np.sin(np.arccos(np.clip(cos, -1.0, 1.0)) / 2.0)

    used, local = np.unique(edges, return_inverse=True)
    local = local.reshape(-1, 2)
    xy = voronoi.vertices[used]
    # A Voronoi vertex is equally far from its generating samples and no sample is nearer
    # (the empty circle): its radius is the distance to either sample of any ridge it ends.
    radius = np.empty(len(used))
    radius[local] = np.linalg.norm(xy[local] - samples[p[keep]][:, None, :], axis=2)
    return _collapse_chains(xy, radius, local, sins)


def _collapse_chains(xy: np.ndarray, radius: np.ndarray, edges: np.ndarray, sins: np.ndarray) -> MedialGraph:
    """Build the branch graph: walk each chain of degree-2 vertices between junctions/ends."""
    n = len(xy)
    degree = np.bincount(edges.ravel(), minlength=n)
    # CSR adjacency: for vertex i, neighbours nbr[start[i]:start[i+1]] via edge ids eid[...]
    order = np.argsort(np.concatenate([edges[:, 0], edges[:, 1]]), kind="stable")
    ends = np.concatenate([edges[:, 1], edges[:, 0]])[order]
    edge_ids = np.concatenate([np.arange(len(edges)), np.arange(len(edges))])[order]
    start = np.concatenate([[0], np.cumsum(degree)])
    nbr, eid = ends.tolist(), edge_ids.tolist()
    start_l, degree_l = start.tolist(), degree.tolist()

    graph = MedialGraph()
    node_of: dict[int, int] = {}

    def node_for(vertex: int) -> int:
        if vertex not in node_of:
            node_of[vertex] = graph.add_node(xy[vertex], radius[vertex])
        return node_of[vertex]

    visited = bytearray(len(edges))
    # For a degree-2 vertex: its two (edge, neighbour) pairs, to step along a chain.
    two = degree == 2
    at = np.minimum(start[:-1], len(ends) - 2)
    first_e, first_n = np.where(two, edge_ids[at], -1).tolist(), np.where(two, ends[at], -1).tolist()
    second_e, second_n = np.where(two, edge_ids[at + 1], -1).tolist(), np.where(two, ends[at + 1], -1).tolist()

    def walk(first: int, k: int) -> None:
        path, path_edges = [first], []
        e = eid[start_l[first] + k]
        cur = nbr[start_l[first] + k]
        while True:
            visited[e] = 1
            path.append(cur)
            path_edges.append(e)
            if degree_l[cur] != 2 or cur in node_of:
                break
            if first_e[cur] != e:
                e2, nxt = first_e[cur], first_n[cur]
            else:
                e2, nxt = second_e[cur], second_n[cur]
            if visited[e2]:
                break
            cur, e = nxt, e2
        a, b = node_for(path[0]), node_for(path[-1])
        graph.add_branch(Branch(a, b, xy[path], radius[path], sins[path_edges]))

    for vertex in np.flatnonzero(degree != 2).tolist():
        node_for(vertex)
    for vertex in np.flatnonzero(degree != 2).tolist():
        for k in range(degree_l[vertex]):
            if not visited[eid[start_l[vertex] + k]]:
                walk(vertex, k)
    # What is left are closed chains of degree-2 vertices: give each one node and walk it.
    for e in np.flatnonzero(np.frombuffer(visited, dtype=np.uint8) == 0).tolist():
        if visited[e]:
            continue
        vertex = int(edges[e, 0])
        node_for(vertex)
        k = eid[start_l[vertex]:start_l[vertex + 1]].index(e)
        walk(vertex, k)
    return graph
