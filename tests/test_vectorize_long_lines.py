"""Very long single lines (TSP art: one closed line through thousands of points, no crossing,
passes a few px apart): not refused as noise, one closed stroke along the tour, and the
fitting's per-corner work stays local."""

from __future__ import annotations


import numpy as np
import pytest

from benchmarks.metrics.table1 import order_score
from benchmarks.common.render import render, to_uint8
from benchmarks.sets.tsp_art import tsp_tour
from vectorize import VectorizeOptions, vectorize_image
from vectorize.drawing import Drawing
from vectorize.fit.fitting import sharp_corners
from vectorize.stroke import Stroke


SIDE = 700


@pytest.mark.slow
def test_tsp_art_is_one_closed_stroke_along_its_tour():
    # 1800 stipples in a 620 px square, 2 px ink: a closed line of ~25,000 px whose outline
    # (~165,000 samples) was refused as "paper texture or noise" (limit 150,000)
    width = 2.0
    poly = tsp_tour(np.random.default_rng(7), 1800, width, 620.0) + 40.0
    truth = Stroke.from_polyline(poly)
    assert truth.length > 24_000
    image = to_uint8(render(Drawing((truth,), SIDE, SIDE, unit="px", stroke_width=width)))
    result = vectorize_image(image, VectorizeOptions(multi=False, classifier="cnn", seed=0))
    assert len(result.drawing.strokes) == 1
    stroke = result.drawing.strokes[0]
    assert stroke.is_closed
    assert order_score(truth, [stroke], 2.0 * width, closed=True) >= 0.98
    from scipy.spatial import cKDTree

    far = cKDTree(truth.sample_evenly(0.25)).query(stroke.sample_evenly(0.5))[0].max()
    assert far <= 0.5 * width + 1.0


def test_sharp_corners_keep_the_sharpest_two_widths_apart():
    # the bisect over kept corners selects what a scan over all of them selects
    rng = np.random.default_rng(1)
    xy = np.cumsum(rng.normal(0.0, 6.0, (600, 2)), axis=0)
    width = 3.0
    found = sharp_corners(xy, width, closed=False)
    assert len(found) > 50
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))]
    gaps = np.diff(arc[found])
    assert gaps.min() > 2.0 * width
