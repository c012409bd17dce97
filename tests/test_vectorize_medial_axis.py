"""The medial axis's Voronoi ridges (built from qhull's Delaunay triangulation) against
scipy's own Voronoi diagram of the same samples."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Voronoi

from vectorize.axis.voronoi import voronoi_part


def _small(points: np.ndarray, vertices: np.ndarray, generator: int) -> bool:
    """Both vertices' circles are smaller than the drawing: the part the medial axis reads
    (ours may also list ridges to flat triangles' centres on a straight convex hull, which
    scipy calls infinite)."""
    return bool(np.all(np.linalg.norm(vertices - points[generator], axis=1) < np.ptp(points, axis=0).max() / 2))


def _finite_ridges(points: np.ndarray) -> dict:
    """scipy's finite ridges as {generating pair: sorted vertex positions}."""
    voronoi = Voronoi(points)
    ridges = {}
    for (p, q), (a, b) in zip(voronoi.ridge_points, voronoi.ridge_vertices):
        if a >= 0 and b >= 0 and _small(points, voronoi.vertices[[a, b]], p):
            ends = sorted(map(tuple, np.round(voronoi.vertices[[a, b]], 6)))
            if ends[0] != ends[1]:
                ridges[tuple(sorted((int(p), int(q))))] = ends
    return ridges


def _ours(points: np.ndarray) -> dict:
    part = voronoi_part(points)
    return {tuple(sorted(map(int, pq))): sorted(map(tuple, np.round(part.center[ab], 6)))
            for pq, ab in zip(part.ridge_points, part.ridges) if _small(points, part.center[ab], pq[0])}


@pytest.mark.parametrize("kind", ["random", "grid", "outline"])
def test_same_ridges_as_scipy_voronoi(kind):
    rng = np.random.default_rng(3)
    if kind == "random":
        points = rng.random((400, 2)) * 100
    elif kind == "grid":
        # Every square of a grid is four cocircular samples: one Voronoi vertex, not two.
        points = np.stack(np.meshgrid(np.arange(12.0), np.arange(9.0)), -1).reshape(-1, 2)
    else:
        # Two evenly sampled sides of a straight stroke and a ring: cocircular quads too.
        t = np.arange(0.0, 40.0, 0.5)
        angle = np.linspace(0, 2 * np.pi, 90, endpoint=False)
        points = np.vstack([np.column_stack([t, np.zeros_like(t)]), np.column_stack([t, np.full_like(t, 4.0)]),
                            np.column_stack([60 + 8 * np.cos(angle), 20 + 8 * np.sin(angle)])])
    theirs, ours = _finite_ridges(points), _ours(points)
    assert ours.keys() == theirs.keys()
    for pair, ends in theirs.items():
        assert np.allclose(ours[pair], ends, atol=1e-5), pair


def _ink(mask: np.ndarray) -> np.ndarray:
    return np.where(mask, 0.0, 1.0).astype(np.float32)


def test_branches_run_from_node_to_node():
    from vectorize.axis.medial_axis import medial_axis
    from vectorize.raster.outline import outline_rings

    yy, xx = np.mgrid[0:160, 0:160]
    ring = _ink(np.abs(np.hypot(xx - 80, yy - 80) - 50) < 4)
    plus = _ink(((np.abs(xx - 80) < 4) & (np.abs(yy - 80) < 60)) | ((np.abs(yy - 80) < 4) & (np.abs(xx - 80) < 60)))
    for gray in (ring, plus):
        graph = medial_axis(outline_rings(gray, 0.5, 0.5), gray, 0.5)
        points = 0
        for branch in graph.branches.values():
            assert np.array_equal(branch.points[0], graph.positions[branch.a])
            assert np.array_equal(branch.points[-1], graph.positions[branch.b])
            assert len(branch.sins) == len(branch.points) - 1 == len(branch.radii) - 1
            points += len(branch.points) - 2
        # Every inner point of a branch is a vertex of no other branch and no node.
        inner = np.vstack([b.points[1:-1] for b in graph.branches.values() if len(b.points) > 2])
        assert len(np.unique(inner, axis=0)) == points
        assert not (set(map(tuple, inner)) & set(tuple(p) for p in graph.positions.values()))
        # Branches are cut from shared arrays: no two of them hold the same memory.
        arrays = [(b.points, b.radii, b.sins) for b in graph.branches.values()]
        for i, first in enumerate(arrays):
            for second in arrays[i + 1:]:
                assert not any(np.shares_memory(x, y) for x, y in zip(first, second))


def test_chains_become_branches_and_a_closed_chain_is_one_loop():
    from vectorize.axis.medial_axis import _collapse_chains

    # A Y (vertex 0 the junction, arms 0-1-2, 0-3, 0-4-5-6) and a separate cycle 7..11.
    edges = np.array([[0, 1], [1, 2], [3, 0], [0, 4], [5, 4], [5, 6], [8, 7], [8, 9], [9, 10], [10, 11], [11, 7]])
    xy = np.column_stack([np.arange(12.0), np.zeros(12)])
    graph = _collapse_chains(xy, np.ones(12), edges, np.arange(len(edges)) / 10.0)
    found = [(graph.positions[b.a][0], b.points[:, 0].tolist(), b.sins.tolist()) for b in graph.branches.values()]
    # A junction's chains in the order of its edges as first, then as second vertex.
    assert found == [(0.0, [0, 1, 2], [0.0, 0.1]), (0.0, [0, 4, 5, 6], [0.3, 0.4, 0.5]), (0.0, [0, 3], [0.2]),
                     (8.0, [8, 7, 11, 10, 9, 8], [0.6, 1.0, 0.9, 0.8, 0.7])]
    assert [graph.degree(n) for n in graph.incident] == [3, 1, 1, 1, 2]


def test_an_axis_of_closed_chains_only_is_one_loop_each():
    """A clean ring's axis has no junction and no end: one node and one loop branch."""
    from vectorize.axis.medial_axis import _collapse_chains

    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [5, 4], [6, 5], [4, 6]])
    xy = np.column_stack([np.arange(7.0), np.zeros(7)])
    graph = _collapse_chains(xy, np.ones(7), edges, np.ones(len(edges)))
    assert [b.points[:, 0].tolist() for b in graph.branches.values()] == [[0, 1, 2, 3, 0], [5, 4, 6, 5]]
    assert [graph.degree(n) for n in graph.incident] == [2, 2]
