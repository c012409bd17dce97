"""Which stretch to retrace is read from the ink where it shows: a glyph drawn out and back a
font unit beside itself (or down one stem twice, a unit apart) leaves a band wider than its
line there, and route inspection retraces that band (`retraces.double_band_weights`) rather
than a shorter branch drawn once."""

from __future__ import annotations

import pytest

from benchmarks.hershey import glyph_ground_truth, glyph_width, load_glyphs
from benchmarks.metrics import ORDER_THRESHOLD, order_score, order_tolerance
from benchmarks.render import render
from vectorize import VectorizeOptions, vectorize_image
from vectorize.graph import Branch, MedialGraph
from vectorize.retraces import DOUBLE_BAND_FLOOR, double_band_weights


@pytest.mark.parametrize("font, name", [
    ("EMSTech", "u"),  # its stem goes up beside the bowl's end and comes down 0-1 width beside it
    ("EMSNixish", "at"),  # the @'s stem drawn down twice, 3 font units apart
])
def test_the_retrace_goes_where_the_ink_shows_two_passes(font, name):
    glyph = next(g for g in load_glyphs() if g.font == font and g.name == name)
    gt = glyph_ground_truth(glyph, glyph_width(glyph, 1))  # as in the hershey set at seed 1
    assert gt is not None
    drawing = vectorize_image(render(gt.drawing), VectorizeOptions(multi=False, classifier="cnn", seed=0)).drawing
    assert len(drawing.strokes) == 1
    # before: the shorter branch was retraced (order 0.72 and 0.92), against the drawn order
    assert order_score(gt.stroke, drawing.strokes, order_tolerance(gt.width), closed=gt.closed) >= ORDER_THRESHOLD


def test_only_a_band_wider_than_the_line_is_cheaper():
    import numpy as np

    graph = MedialGraph()
    a, b, c = (graph.add_node(np.array(p, dtype=float), 2.0) for p in ([0, 0], [100, 0], [200, 0]))
    x = np.linspace(0, 100, 101)
    one = graph.add_branch(Branch(a, b, np.c_[x, 0 * x], np.full(101, 2.0), np.ones(100)))  # w = 4
    two = graph.add_branch(Branch(b, c, np.c_[x + 100, 0 * x], np.full(101, 2.8), np.ones(100)))  # 1.4 w wide
    wide = graph.add_branch(Branch(a, c, np.c_[x * 2, 0 * x + 50], np.full(101, 5.0), np.ones(100)))
    weights = double_band_weights(graph, 4.0)
    assert one not in weights
    assert weights[two] == pytest.approx(0.6)
    assert weights[wide] == DOUBLE_BAND_FLOOR
