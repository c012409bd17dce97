"""A narrow cusp keeps its tip: where both sides of a handwritten i or n merge into one blob
of ink before the tip, the medial axis turns back short of it; the fitted corner goes where
the ink shows the pen turned (`fit.tips.tip_in_ink`), not where the axis turned."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.handwriting import handwriting_drawing
from benchmarks.metrics.ink import excursion_bound, ink_scores
from benchmarks.metrics.table1 import order_tolerance
from benchmarks.common.render import render
from vectorize import VectorizeOptions, vectorize_image


@pytest.mark.parametrize("index, tip", [
    (20, (453.0, 516.0)),  # hand-kind-1-20, 7.5 px: the i's tip was cut 11 px short
    (16, (423.0, 501.0)),  # hand-tilde-1-16, 3 px: the i's tip was cut 4 px short
])
def test_narrow_cusp_tip_is_reached(index, tip):
    gt = handwriting_drawing(1, index)
    result = vectorize_image(render(gt.drawing), VectorizeOptions(multi=False, classifier="cnn", seed=0))
    drawing = result.drawing
    assert len(drawing.strokes) == 1
    samples = drawing.strokes[0].sample_evenly(0.25)
    # The pen's turning point at the cusp lies within the order score's tolerance of the curve.
    gap = float(np.linalg.norm(samples - np.array(tip), axis=1).min())
    assert gap < order_tolerance(gt.width) / 2
    scores = ink_scores(gt, drawing, order_tolerance(gt.width))
    assert scores.uncovered <= order_tolerance(gt.width)
    # Reaching into the tip does not leave the ink.
    assert scores.excursion <= excursion_bound(gt.width)
