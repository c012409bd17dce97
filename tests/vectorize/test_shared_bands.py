"""A short band of ink two passes share: the route keeps each pass's own heading through it
(`vectorize.route.route_inspection.shared_bands`)."""

from __future__ import annotations

import pytest

from tests.drawings import cursive_stretch
from vectorize import VectorizeOptions, vectorize_image


@pytest.mark.parametrize("seed, index, center, half", [
    (0, 11, (130.0, 480.0), 85.0),  # "han" of handy_lady_tidy_attic, 3 px: order 0.855 before
    (0, 7, (330.0, 490.0), 90.0),  # "l the" of mail_the_ticket_at_ten, 3.25 px: order 0.873 before
])
def test_an_h_loop_is_drawn_the_way_its_way_in_heads(seed, index, center, half):
    """A cursive h: the way in crosses the loop's way down, and between that crossing and the
    junction where the loop closes, the way in and the stem drawn back up share one short
    band (4 widths). Leaving the band into the loop, the pen takes the loop's side that
    continues the way in's heading; the band's own axis runs between the two passes'
    headings and pointed into the loop's other side, so the loop was drawn backwards."""
    from benchmarks.common.render import render
    from benchmarks.metrics.table1 import ORDER_THRESHOLD, order_score, order_tolerance

    drawing, _ = cursive_stretch(seed, index, center, half)
    result = vectorize_image(render(drawing), VectorizeOptions(classifier="cnn"))
    assert result.report.strokes == 1
    order = order_score(drawing.strokes[0], result.drawing.strokes, order_tolerance(drawing.stroke_width))
    assert order >= ORDER_THRESHOLD
