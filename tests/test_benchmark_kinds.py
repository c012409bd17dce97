"""The `kinds` benchmark set's machinery: TSP tours, variable-width rendering and excursion,
brush profiles and phone photos (benchmarks/sets/tsp_art.py, brush.py, photo.py, kinds.py)."""

from __future__ import annotations


import numpy as np
import shapely

from benchmarks.sets.brush import THIN, brush_profile, kana_set, nib_profile
from benchmarks.metrics.ground_truth import interleaved
from benchmarks.metrics.ink import ink_scores
from benchmarks.metrics.table1 import polyline_intersections
from benchmarks.sets.photo import apply_homography, photo_image, photographed
from benchmarks.common.render import render_profile
from benchmarks.sets.tsp_art import tsp_tour
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def test_a_tsp_tour_is_closed_never_crosses_and_keeps_paper_between_its_passes():
    width = 2.5
    poly = tsp_tour(np.random.default_rng(3), 400, width, 400.0)
    assert np.array_equal(poly[0], poly[-1]) and len(poly) > 300
    inter = polyline_intersections([poly], [True])
    assert len(inter.crossings) == 0 and len(inter.touches) == 0
    edges = shapely.linestrings(np.stack([poly[:-1], poly[1:]], axis=1))
    n = len(edges)
    left, right = shapely.STRtree(edges).query(edges, predicate="dwithin", distance=width + 2.0)
    far = ((right - left) % n > 1) & ((left - right) % n > 1)
    assert not far.any()  # non-neighbouring parts of the line are more than w + 2 px apart


def _ink_width(gray: np.ndarray, column: int) -> float:
    return float((1.0 - gray[:, column]).sum())  # ink coverage summed across a horizontal line


def test_render_profile_draws_the_local_width_along_the_line():
    line = Stroke.from_polyline(np.array([[20.0, 50.0], [180.0, 50.0]]))
    drawing = Drawing((line,), 200, 100, unit="px", stroke_width=9.0)
    gray = render_profile(drawing, (np.array([0.0, 1.0]), np.array([3.0, 9.0])))
    for x in (40, 100, 160):
        expected = 3.0 + 6.0 * (x + 0.5 - 20.0) / 160.0
        assert abs(_ink_width(gray, x) - expected) < 0.1


def test_the_excursion_bound_follows_the_local_width():
    from benchmarks.metrics.ground_truth import GroundTruth

    line = Stroke.from_polyline(np.array([[20.0, 50.0], [180.0, 50.0]]))
    drawing = Drawing((line,), 200, 100, unit="px", stroke_width=9.0)
    gt = GroundTruth("line", "test", drawing, False, np.zeros((0, 2)),
                     meta={"width_profile": (np.array([0.0, 1.0]), np.array([3.0, 9.0]))})
    # 4 px off the centre line: inside where the ink is 9 px wide (4.5 + 1), outside at 3 px (1.5 + 1)
    wide_end = Stroke.from_polyline(np.array([[150.0, 54.0], [180.0, 54.0]]))
    thin_end = Stroke.from_polyline(np.array([[20.0, 54.0], [50.0, 54.0]]))
    ok = ink_scores(gt, drawing.with_strokes([wide_end]), 10.0)
    bad = ink_scores(gt, drawing.with_strokes([thin_end]), 10.0)
    assert ok.within and ok.headroom > 0 and abs(ok.excursion - 4.0) < 1e-6
    assert not bad.within and bad.headroom < 0 and bad.excursion_widths > 1.0


def test_brush_and_nib_widths_vary_threefold():
    f, w = brush_profile(np.random.default_rng(0), 600.0, 12.0)
    assert w.min() >= THIN * 12.0 - 1e-9 and w.max() <= 12.0 + 1e-9
    assert w[0] < 0.4 * 12.0  # the brush presses in
    circle = Stroke(np.array([[[100, 0], [155, 0], [200, 45], [200, 100]], [[200, 100], [200, 155], [155, 200],
                                                                              [100, 200]]], dtype=float))
    _, nib = nib_profile(circle, 12.0, np.radians(-30.0))
    assert nib.max() / nib.min() > 2.5  # across the nib thick, along it thin
    kana = kana_set(3)
    assert len(kana) == 3 and all("width_profile" in gt.meta for gt in kana)


def test_a_photo_moves_the_ground_truth_and_darkens_the_page_unevenly():
    source = kana_set(1)[0]
    gt = photographed(source, np.random.default_rng(1))
    h = np.array(gt.meta["homography"])
    start = apply_homography(h, source.stroke.start[None])[0]
    assert np.allclose(gt.stroke.start, start, atol=1e-6)
    assert gt.kind == "photo" and gt.meta["condition"] == "photo"
    image = photo_image(np.ones((200, 300)), np.random.default_rng(2))
    assert image.shape == (200, 300, 3) and image.dtype == np.uint8
    lum = image.mean(axis=2)
    corners = [lum[:20, :20].mean(), lum[:20, -20:].mean(), lum[-20:, :20].mean(), lum[-20:, -20:].mean()]
    assert max(corners) - min(corners) > 20  # light falloff and shadow: not one paper level


def test_sets_mix_their_sources_one_of_each_in_turn():
    queues = [["a1", "a2", "a3"], [], ["b1"], ["c1", "c2"]]
    assert interleaved(queues) == ["a1", "b1", "c1", "a2", "c2", "a3"]
    assert interleaved(queues, 4) == ["a1", "b1", "c1", "a2"]
    assert interleaved(queues, 10) == interleaved(queues) and interleaved(queues, 0) == []
    assert interleaved([[None, 0], [""]]) == [None, "", 0]  # falsy items are items too
