"""The medial axis computed in parallel tiles (and from jittered qhull input) is the one of
the whole exact diagram: the same kept ridges, the same graph, on real and made drawings."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import Voronoi

import vectorize.axis.medial_axis as medial
import vectorize.axis.voronoi as voronoi
from vectorize.axis.medial_axis import _inside, medial_axis
from vectorize.raster.binarize import binarize
from vectorize.raster.image_io import load_image
from vectorize.raster.outline import outline_rings

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _example(name: str):
    """The medial axis's inputs for an example, as the vectorizer makes them."""
    ink = binarize(load_image(EXAMPLES / name)[0], max_size=1000, blur=0.0, threshold=None)
    spacing = float(np.clip(ink.stroke_width / 8.0, 0.3, 1.0))
    return outline_rings(ink.gray, ink.threshold, spacing), ink.gray, ink.threshold


def _made(kind: str):
    """Made drawings (gray 0 ink / 1 paper, level 0.5): a wide blob across the middle tile cut on a line running off
    both image edges; a tiny ring; a long thin wave on a wide canvas."""
    if kind == "blob":
        yy, xx = np.mgrid[0:420, 0:1800]
        ink = (np.abs(yy - 200 - 60 * np.sin(xx / 150.0)) < 4) | (np.hypot(xx - 1020, yy - 210) < 70)
        ink |= (np.abs(xx - 1400) < 3) & (yy > 50)  # a stroke into the bottom edge
    elif kind == "tiny":
        yy, xx = np.mgrid[0:40, 0:48]
        ink = np.abs(np.hypot(xx - 24, yy - 20) - 12) < 2.5
    else:
        yy, xx = np.mgrid[0:500, 0:3000]
        ink = (np.abs(yy - 250 - 200 * np.sin(xx / 97.0) * np.cos(xx / 1300.0)) < 3) & (xx > 20) & (xx < 2980)
    gray = np.where(ink, 0.0, 1.0).astype(np.float32)
    return outline_rings(gray, 0.5, 0.5), gray, 0.5


def _segments(graph) -> set:
    """The graph's kept ridges as a set of vertex coordinate pairs."""
    out = set()
    for branch in graph.branches.values():
        points = [tuple(p) for p in branch.points.tolist()]
        out.update(tuple(sorted(pair)) for pair in zip(points[:-1], points[1:]))
    return out


def _arrays(graph) -> list:
    return [(b.a, b.b, b.points.tobytes(), b.radii.tobytes(), b.sins.tobytes()) for b in graph.branches.values()]


def _reference(rings, gray, level) -> set:
    """The kept ridges from scipy's own Voronoi diagram of the exact samples (no tiles, no
    jitter), rounded to 1e-6 px: both vertices inside, samples not ring neighbours."""
    samples = np.vstack(rings)
    ring_of = np.repeat(np.arange(len(rings)), [len(r) for r in rings])
    index = np.concatenate([np.arange(len(r)) for r in rings])
    size = np.array([len(r) for r in rings])[ring_of]
    diagram = Voronoi(samples)
    pairs, ends = diagram.ridge_points, np.array(diagram.ridge_vertices)
    finite = (ends >= 0).all(1)
    pairs, ends = pairs[finite], ends[finite]
    gap = np.abs(index[pairs[:, 0]] - index[pairs[:, 1]])
    gap = np.minimum(gap, size[pairs[:, 0]] - gap)
    apart = ~((ring_of[pairs[:, 0]] == ring_of[pairs[:, 1]]) & (gap <= 1))
    inside = _inside(gray, level, diagram.vertices)
    kept = ends[apart & inside[ends[:, 0]] & inside[ends[:, 1]]]
    out = set()
    for a, b in np.round(diagram.vertices[kept], 6).tolist():
        if a != b:
            out.add(tuple(sorted((tuple(a), tuple(b)))))
    return out


def _rounded(segments: set) -> set:
    out = set()
    for a, b in segments:
        a, b = tuple(np.round(a, 6)), tuple(np.round(b, 6))
        if a != b:
            out.add(tuple(sorted((a, b))))
    return out


@pytest.mark.parametrize("source", ["loops.png", "hershey-HersheySans1-ampersand.png", "blob", "tiny", "wave"])
def test_tiles_give_the_whole_diagrams_axis(source):
    rings, gray, level = _example(source) if source.endswith(".png") else _made(source)
    whole = medial_axis(rings, gray, level, tiles=1)
    assert len(whole.branches) > 0
    for tiles in (2, 3, 5):
        tiled = medial_axis(rings, gray, level, tiles=tiles)
        assert _segments(tiled) == _segments(whole)
        # The same graph: vertex and branch order do not depend on the tiling.
        assert _arrays(tiled) == _arrays(whole)
    if source in ("loops.png", "blob"):
        assert _rounded(_segments(whole)) == _reference(rings, gray, level)


def test_tiles_are_used_and_a_too_small_margin_falls_back(monkeypatch):
    rings, gray, level = _made("blob")
    whole = _segments(medial_axis(rings, gray, level, tiles=1))
    calls = []
    part = voronoi.voronoi_part

    def counted(*args, **kwargs):
        calls.append(len(args[1]) if len(args) > 1 and args[1] is not None else None)
        return part(*args, **kwargs)

    monkeypatch.setattr(medial, "voronoi_part", counted)
    assert _segments(medial_axis(rings, gray, level, tiles=2)) == whole
    assert len(calls) == 2 and None not in calls  # two tiles, no whole diagram
    # A margin far below the blob's radius: tiles see inside vertices whose circles do not
    # fit them, and the whole diagram is computed instead.
    calls.clear()
    monkeypatch.setattr(medial, "empty_circle_bound", lambda *args: 3.0)
    assert _segments(medial_axis(rings, gray, level, tiles=2)) == whole
    assert calls[-1] is None


@pytest.mark.parametrize("cores", [1, 2, 3])
def test_work_beside_qhull_runs_once_in_this_thread_and_keeps_the_graph(monkeypatch, cores):
    """`beside` (a first call's imports of the later stages) runs once, in the calling
    thread; with a core to spare qhull works in another thread meanwhile (the whole
    triangulation on two cores, tiles on more), with the same graph as without it."""
    rings, gray, level = _made("blob")
    whole = _arrays(medial_axis(rings, gray, level, tiles=1))
    monkeypatch.setattr(medial, "idle_cores", lambda: cores)
    parts, triangulations, beside = [], [], []
    part, triangulate = voronoi.voronoi_part, voronoi.jittered_delaunay

    def recorded_part(*args, **kwargs):
        parts.append(threading.get_ident())
        return part(*args, **kwargs)

    def recorded_triangulation(*args, **kwargs):
        triangulations.append(threading.get_ident())
        return triangulate(*args, **kwargs)

    monkeypatch.setattr(medial, "voronoi_part", recorded_part)
    monkeypatch.setattr(medial, "jittered_delaunay", recorded_triangulation)
    graph = medial_axis(rings, gray, level, beside=lambda: beside.append(threading.get_ident()))
    assert _arrays(graph) == whole
    this = threading.get_ident()
    assert beside == [this]
    if cores == 1:  # `beside` first, then the whole diagram here
        assert parts == [this] and triangulations == []
    elif cores == 2:  # qhull elsewhere, the diagram made of its triangulation here
        assert parts == [this] and len(triangulations) == 1 and this not in triangulations
    else:  # a tile per spare core, each in a thread of its own
        assert len(parts) == 2 and this not in parts and triangulations == []


@pytest.mark.parametrize("source", ["loops.png", "touch-drawing.png", "blob", "tiny"])
def test_empty_circle_bound_holds(source):
    rings, gray, level = _example(source) if source.endswith(".png") else _made(source)
    samples = np.vstack(rings)
    spacing = max(float(np.linalg.norm(np.diff(r, axis=0, append=r[:1]), axis=1).max()) for r in rings)
    bound = voronoi.empty_circle_bound(samples, gray, level, spacing)
    largest = max(b.radii.max() for b in medial_axis(rings, gray, level, tiles=1).branches.values())
    assert largest <= bound <= 3 * largest + 6


def test_a_jitter_that_flips_a_near_cocircular_square_is_refused(monkeypatch):
    """A grid with one sample a few 1e-9 px off its squares' circles: the exact diagonals
    are decided, the jittered ones a coin toss. A wrong toss is refused and the exact points
    are triangulated: the diagram is the exact one either way."""
    points = np.stack(np.meshgrid(np.arange(6.0), np.arange(5.0)), -1).reshape(-1, 2)

    def pairs(part) -> set:
        """Generating pairs of the ridges between circles smaller than the grid (not those to
        the slivers a jitter makes of the straight convex hull, flat at the exact points)."""
        small = part.radius[part.ridges].max(axis=1) < 5.0
        return {tuple(sorted(pq)) for pq in part.ridge_points[small].tolist()}

    def edges(mesh) -> set:
        _, _, radius, first, second, ridge_points, same = mesh
        keep = ~same & (radius[first] < 5.0) & (radius[second] < 5.0)
        return {tuple(sorted(pq)) for pq in ridge_points[keep].tolist()}

    refused = 0
    for shift in np.linspace(-4e-9, 4e-9, 9):
        moved = points.copy()
        moved[14] += shift
        span = float(np.ptp(moved, axis=0).max()) + 1.0
        jitter = np.random.default_rng(voronoi.JITTER_SEED).uniform(-voronoi.JITTER, voronoi.JITTER, moved.shape)
        tossed = voronoi._triangulation(moved, jitter, span)
        exact = voronoi._triangulation(moved, None, span)
        ours = pairs(voronoi.voronoi_part(moved))
        with monkeypatch.context() as patch:
            patch.setattr(voronoi, "JITTER", 0.0)
            assert ours == pairs(voronoi.voronoi_part(moved))
        if tossed is None:
            refused += 1
        else:
            # Accepted: the exact triangulation's edges, but where both triangles are one
            # vertex (a cocircular square's diagonal).
            assert edges(tossed) == edges(exact)
    assert refused > 0


def test_sides_are_numpys_ptp():
    rng = np.random.default_rng(2)
    for size in (1, 2, 9, 20_000):
        points = rng.normal(size=(size, 2)) * [300.0, 7.0] + [500.0, -3.0]
        assert np.array_equal(voronoi.sides(points), np.ptp(points, axis=0))
