"""The crossing CNN shown only a junction's own ink (`vectorize.junctions.junction_ink`,
`junction_crop.crop_own_ink`): what ink is kept, the crops it gives, and cursive lines."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from vectorize.axis.graph import Branch, MedialGraph
from vectorize.junctions.junction_crop import crop_junctions, crop_own_ink
from vectorize.junctions.junction_ink import MAX_REACH, MIN_REACH, own_ink, own_ink_reach

W = 4.0  # px stroke width of the constructed graph


def _join(graph: MedialGraph, a: int, b: int) -> int:
    """A straight branch from node a to b, a point every px, radius W / 2."""
    pa, pb = graph.positions[a], graph.positions[b]
    n = int(np.ceil(np.linalg.norm(pb - pa))) + 1
    points = pa + np.linspace(0.0, 1.0, n)[:, None] * (pb - pa)
    return graph.add_branch(Branch(a, b, points, np.full(n, W / 2), np.ones(n - 1)))


def _crossing_beside_a_stem() -> tuple[MedialGraph, int]:
    """A crossing at (0, 0) of two lines; 3 W out along the right branch a fork, where the
    line runs straight on and an h's stem leaves upwards. Returns the graph and the crossing."""
    graph = MedialGraph()
    node = lambda x, y: graph.add_node(np.array([x, y], float), W / 2)  # noqa: E731
    crossing, fork = node(0.0, 0.0), node(3 * W, 0.0)
    for x, y in ((-60.0, 0.0), (0.0, -60.0), (0.0, 60.0)):
        _join(graph, crossing, node(x, y))
    _join(graph, crossing, fork)
    _join(graph, fork, node(60.0, 0.0))  # straight on
    _join(graph, fork, node(3 * W + 5.0, -60.0))  # the stem, 85 degrees off
    return graph, crossing


def test_own_ink_follows_each_line_straight_on_out_to_the_reach():
    graph, crossing = _crossing_beside_a_stem()
    ink = own_ink(graph, crossing, 6 * W, W)
    xy = ink[:, :2]
    assert np.allclose(ink[:, 2], W / 2)
    # Every branch out to 6 W of arc and not further, the right one on past the fork ...
    for end in ((-6 * W, 0.0), (0.0, -6 * W), (0.0, 6 * W), (6 * W, 0.0)):
        assert np.linalg.norm(xy - end, axis=1).min() < 1.0
    assert np.abs(xy).max() <= 6 * W + 1e-9
    # ... and none of the stem leaving the fork.
    assert not np.any((xy[:, 1] < -1.0) & (xy[:, 0] > 1.0))


@pytest.mark.parametrize("degrees, reach", [(90.0, MIN_REACH), (60.0, MIN_REACH), (40.0, 5.0 / np.sin(np.radians(40.0))),
                                            (30.0, MAX_REACH), (10.0, MAX_REACH)])
def test_the_shallower_the_crossing_the_more_line_is_kept(degrees, reach):
    t = np.radians(degrees)
    directions = np.array([[1.0, 0.0], [np.cos(t), np.sin(t)], [-1.0, 0.0], [-np.cos(t), -np.sin(t)]])
    assert own_ink_reach(directions, W) == pytest.approx(reach * W)


def _strokes(width: float, size: int = 400) -> np.ndarray:
    """Two strokes crossing at (200, 210) and a third passing 3 widths from the crossing."""
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    d1 = np.abs((xx - 200) * np.sin(0.3) - (yy - 210) * np.cos(0.3))
    d2 = np.abs((xx - 200) * np.sin(1.4) - (yy - 210) * np.cos(1.4))
    d3 = np.abs(yy - 210 - 3 * width)
    ink = np.clip(width / 2 - np.minimum(np.minimum(d1, d2), d3) + 0.5, 0, 1)
    return (1.0 - 0.9 * ink).astype(np.float32)


@pytest.mark.parametrize("width", [2.5, 4.0, 10.0])
def test_own_ink_crops_are_the_crops_of_the_masked_image(width):
    """Crops cut from a small masked window equal those of the whole image masked the same
    way (the window is aligned to the crops' block grids), and the third stroke is gone."""
    gray = _strokes(width)
    s = np.linspace(-6 * width, 6 * width, 60)
    ink = np.concatenate([np.c_[200 + s * np.cos(a), 210 + s * np.sin(a), np.full(60, width / 2)] for a in (0.3, 1.4)])
    yy, xx = np.mgrid[0:gray.shape[0], 0:gray.shape[1]].astype(float)
    inside = np.zeros(gray.shape, bool)
    for x, y, r in ink:
        inside |= (xx - x) ** 2 + (yy - y) ** 2 <= (r + 1.5) ** 2
    masked = np.where(inside, gray, 1.0).astype(np.float32)
    center = np.array([[200.0, 210.0]])
    own = crop_own_ink(gray, center, [ink], width)
    assert np.allclose(own, crop_junctions(masked, center, width), atol=1e-6)
    assert not np.allclose(own, crop_junctions(gray, center, width), atol=0.05)


def _junctions_at_crossings(seed: int, index: int):
    """A cursive set line through the pipeline: its ground truth, working image, stroke
    width and the classified junctions nearest each ground-truth crossing (within 5 px)."""
    from benchmarks.common.render import render_truth
    from benchmarks.sets.cursive import cursive_drawing
    from vectorize import VectorizeOptions, vectorize_image

    gt = cursive_drawing(seed, index)
    stages = vectorize_image(render_truth(gt), VectorizeOptions(classifier="cnn", keep_stages=True)).stages
    junctions = list(stages["junctions"].values())
    centers = np.array([j.center for j in junctions])
    crossings = np.asarray(gt.intersections, dtype=float).reshape(-1, 2)
    near = [junctions[int(np.argmin(np.linalg.norm(centers - c, axis=1)))] for c in crossings
            if np.linalg.norm(centers - c, axis=1).min() < 5.0]
    return gt, stages["ink"].gray, stages["ink"].stroke_width, near


def test_the_cnn_reads_a_cursive_lines_crossings_from_their_own_ink():
    """'the little duck had tea' (seed 0): of the line's 10 crossings, the base of the first
    h ("the") is read from its medial tree (`stem_clusters`) and never shown to the model; of
    the other 9, with the whole word in its far crop, the shipped model calls 5 crossings,
    shown each junction's own ink, 8 (measured; the one missed is the second h's base)."""
    from vectorize.junctions.classifiers import make_classifier

    _, gray, width, near = _junctions_at_crossings(0, 13)
    assert len(near) == 9 and all(j.ink is not None for j in near)
    cnn = make_classifier("cnn")
    own = [v.is_crossing for v in cnn.classify(gray, near, width)]
    whole = [v.is_crossing for v in cnn.classify(gray, [dataclasses.replace(j, ink=None) for j in near], width)]
    assert sum(own) >= 8 and sum(whole) <= 5


def test_a_cursive_line_crosses_where_its_h_loops_cross():
    """'mechanically' (seed 1): the output makes every crossing of the ground truth (the
    benchmark's 5 px), including the h's loop base the whole-word crop read as a touch."""
    from benchmarks.common.render import render_truth
    from benchmarks.metrics.table1 import MATCH_DISTANCE, drawing_polylines, polyline_intersections
    from benchmarks.sets.cursive import cursive_drawing
    from vectorize import VectorizeOptions, vectorize_image

    gt = cursive_drawing(1, 4)
    result = vectorize_image(render_truth(gt), VectorizeOptions(classifier="cnn"))
    assert result.report.strokes == 1
    found = polyline_intersections(*drawing_polylines(result.drawing))
    points = np.vstack([found.crossings, found.multiple])
    for crossing in np.asarray(gt.intersections, dtype=float).reshape(-1, 2):
        assert np.linalg.norm(points - crossing, axis=1).min() <= MATCH_DISTANCE


def test_a_clean_crossing_keeps_the_confidence_of_the_whole_image():
    """examples/loops.png: cut to its own few widths of line, each clean crossing still reads
    as a crossing but with 5-7 of 8 votes (measured); the whole image gives 8 of 8, and where
    the two agree the confidence shown is the larger. p_crossing is the own ink's."""
    from PIL import Image

    from vectorize import VectorizeOptions, vectorize_image
    from vectorize.junctions.classifiers import make_classifier
    from vectorize.junctions.junction_crop import crop_own_ink

    image = np.asarray(Image.open(Path(__file__).parents[2] / "examples" / "loops.png").convert("L"))
    stages = vectorize_image(image, VectorizeOptions(classifier="cnn", keep_stages=True)).stages
    gray, width = stages["ink"].gray, stages["ink"].stroke_width
    junctions = list(stages["junctions"].values())
    assert len(junctions) == 3 and all(j.ink is not None for j in junctions)
    cnn = make_classifier("cnn")
    verdicts = cnn.classify(gray, junctions, width)
    centers = np.array([j.crop_center for j in junctions])
    own_p, own_share = cnn.predict_crops(crop_own_ink(gray, centers, [j.ink for j in junctions], width))
    assert np.allclose([v.p_crossing for v in verdicts], own_p, atol=1e-6)
    assert all(v.is_crossing and v.confidence == 1.0 for v in verdicts)
    assert own_share.min() < 1.0


def test_the_whole_image_is_read_only_for_a_confidence_shown():
    """Without `whole_image_confidence` (the CLI's default) the CNN reads each junction from
    its own ink only: the same p_crossing bits and the same SVG, the own ink's vote share as
    the confidence. The studio and --debug ask for the whole image's reading as well."""
    from PIL import Image

    from fabrication.studio.session import StudioSession
    from vectorize import VectorizeOptions, vectorize_image
    from vectorize.junctions.classifiers import make_classifier
    from vectorize.svg_write import drawing_to_svg

    loops = Path(__file__).parents[2] / "examples" / "loops.png"
    image = np.asarray(Image.open(loops).convert("L"))
    fast = vectorize_image(image, VectorizeOptions(keep_stages=True))
    shown = vectorize_image(image, VectorizeOptions(keep_stages=True, whole_image_confidence=True))
    assert drawing_to_svg(fast.drawing) == drawing_to_svg(shown.drawing)
    fast_v, shown_v = fast.stages["verdicts"], shown.stages["verdicts"]
    assert len(fast_v) == 3 and fast_v.keys() == shown_v.keys()
    assert [fast_v[n].p_crossing for n in fast_v] == [shown_v[n].p_crossing for n in fast_v]
    assert all(v.confidence == 1.0 for v in shown_v.values())
    assert min(v.confidence for v in fast_v.values()) < 1.0  # 5-7 of 8 votes from the own ink

    cnn = make_classifier("cnn")
    gray, width = fast.stages["ink"].gray, fast.stages["ink"].stroke_width
    junctions = list(fast.stages["junctions"].values())
    junctions.append(dataclasses.replace(junctions[0], ink=None))  # read whole either way
    own_only, both = cnn.classify(gray, junctions, width, whole_image=False), cnn.classify(gray, junctions, width)
    assert [v.p_crossing for v in own_only] == [v.p_crossing for v in both]
    assert own_only[-1] == both[-1]
    assert StudioSession(loops).options.whole_image_confidence
