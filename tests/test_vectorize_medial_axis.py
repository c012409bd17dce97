"""The medial axis's Voronoi ridges (built from qhull's Delaunay triangulation) against
scipy's own Voronoi diagram of the same samples."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Voronoi

from vectorize.medial_axis import voronoi_ridges


def _finite_ridges(points: np.ndarray) -> dict:
    """scipy's finite ridges as {generating pair: sorted vertex positions}."""
    voronoi = Voronoi(points)
    ridges = {}
    for (p, q), (a, b) in zip(voronoi.ridge_points, voronoi.ridge_vertices):
        if a >= 0 and b >= 0:
            ends = sorted(map(tuple, np.round(voronoi.vertices[[a, b]], 6)))
            if ends[0] != ends[1]:
                ridges[tuple(sorted((int(p), int(q))))] = ends
    return ridges


def _ours(points: np.ndarray) -> dict:
    vertices, ridges, generators = voronoi_ridges(points)
    return {tuple(sorted(map(int, pq))): sorted(map(tuple, np.round(vertices[ab], 6)))
            for pq, ab in zip(generators, ridges)}


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
