"""A crossing whose two passes share a short stub to the next junction: the passes cross
there, they do not run together over the stub (`vectorize.vectorizer._shared_stub_reach`)."""

from __future__ import annotations

import numpy as np
from shapely.geometry import LineString


def test_an_l_loop_closing_a_stub_above_its_crossing_is_crossed():
    """the_kitten_ate_the_mauled_candy-1-30's "th": the t's loop closes at a junction 3 px
    (about 2 widths) above the crossing of the way in and the way down, so both passes run
    over that stub. Before, the crossing's zone ended short of the stub's far junction, both
    fitted passes kept its point and ran together 0.1-0.3 px apart, touching in 55 points
    (whether the metric then found a crossing within 5 px depended on the noise: not at
    7e3a111, by chance at 691d66f). The whole line, as the benchmark gives it: stretches cut
    from it with `cursive_stretch` (40-100 px around the crossing) crossed on the old code too."""
    from benchmarks.common.render import render_truth, to_uint8
    from benchmarks.metrics.table1 import MATCH_DISTANCE, drawing_polylines, polyline_intersections
    from benchmarks.sets.cursive import cursive_drawing
    from vectorize import VectorizeOptions, vectorize_image

    gt = cursive_drawing(1, 30)
    crossings = np.asarray(gt.intersections, dtype=float).reshape(-1, 2)
    truth = crossings[np.argmin(np.linalg.norm(crossings - [486.0, 494.5], axis=1))]
    result = vectorize_image(to_uint8(render_truth(gt)), VectorizeOptions(multi=False, classifier="cnn", seed=0))
    assert result.report.strokes == 1
    found = polyline_intersections(*drawing_polylines(result.drawing))
    points = np.vstack([found.crossings, found.multiple])
    assert np.linalg.norm(points - truth, axis=1).min() <= MATCH_DISTANCE
    # The way in and the way down (the first two passes within 6 px) meet once: they cross.
    line = result.drawing.strokes[0].sample_evenly(0.1)
    near = np.flatnonzero(np.linalg.norm(line - truth, axis=1) < 6.0)
    runs = np.split(near, np.flatnonzero(np.diff(near) > 1) + 1)
    way_in, way_down = (LineString(line[run[0]:run[-1] + 1]) for run in runs[:2])
    assert way_in.intersection(way_down).geom_type == "Point"
