"""Hand jitter: a retraced stroke whose two passes wobble around each other within a width
is one retraced stroke with no crossings; a real crossing of jittered lines stays one."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.handwriting import _wobble
from benchmarks.metrics.table1 import drawing_polylines, polyline_intersections
from benchmarks.common.render import render
from vectorize import VectorizeOptions, vectorize_image
from vectorize.drawing import Drawing
from vectorize.fit.retraces import Twin, retraced_runs, trimmed_twins, valid_twins
from vectorize.stroke import Stroke

SIZE = 400


def _jittered(path, width: float, seed: int) -> np.ndarray:
    """The path as a mouse records it (benchmarks/sets/handwriting.py): samples every ~5 px, a
    slow wobble of up to 0.4 widths along the path and 0.3 px corner noise, rounded."""
    rng = np.random.default_rng(seed)
    clean = Stroke.from_polyline(np.asarray(path, dtype=float))
    s = np.arange(0.0, clean.length, 5.0)
    s = np.append(s, clean.length)
    pts = clean.points_at_lengths(s) + _wobble(rng, s, 0.4 * width)
    return np.round(pts + rng.normal(0.0, 0.3, pts.shape))


def _vectorize(polyline: np.ndarray, width: float, multi: bool = False):
    drawing = Drawing((Stroke.from_polyline(polyline),), SIZE, SIZE, unit="px", stroke_width=width)
    return vectorize_image(render(drawing), VectorizeOptions(classifier="geometric", multi=multi, seed=0))


def _crossings(drawing) -> np.ndarray:
    polys, closed = drawing_polylines(drawing)
    return polyline_intersections(polys, closed).crossings


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_jittered_retraced_stem_is_one_retraced_stroke_without_crossings(seed):
    width = 5.0
    # Along a baseline, up a stem and back down it, on along the baseline: the stem's two
    # passes wobble around each other (each on its own, up to 0.4 widths). The stem is the
    # shortest branch, so retracing it is the cheapest way to draw this in one stroke.
    path = [(40, 300), (180, 300), (196, 180), (180, 300), (360, 300)]
    trace = _jittered(path, width, seed)
    # The jittered passes do cross each other: that is what the vectorizer must see through.
    assert len(polyline_intersections([trace], [False]).crossings) > 0
    result = _vectorize(trace, width)
    assert result.report.strokes == 1
    assert result.report.intersections == 0
    assert len(_crossings(result.drawing)) == 0
    # Drawn as the pen did: the stem twice (121 px each way), the baseline once.
    stem = float(np.hypot(16, 120))
    assert result.drawing.strokes[0].length == pytest.approx(320 + 2 * stem, rel=0.05)


def test_jittered_crossing_stays_one_crossing():
    width = 5.0
    # An open curve that loops once and crosses itself at about 60 degrees.
    t = np.linspace(-2.9, 2.9, 600)
    loop = np.c_[200 + 45 * t - 110 * np.sin(t), 200 - 110 * np.cos(t)]
    trace = _jittered(loop, width, seed=4)
    truth = polyline_intersections([trace], [False]).crossings
    assert len(truth) == 1
    result = _vectorize(trace, width)
    assert result.report.strokes == 1
    assert result.report.intersections == 1
    found = _crossings(result.drawing)
    assert len(found) == 1
    assert np.linalg.norm(found[0] - truth[0]) < 5.0


def test_jittered_x_of_two_lines_stays_a_crossing():
    width = 4.0
    # Two separate jittered lines crossing at 40 degrees (multi-line mode: two strokes).
    a = _jittered([(60, 120), (340, 280)], width, seed=5)
    b = _jittered([(60, 280), (340, 180)], width, seed=6)
    drawing = Drawing((Stroke.from_polyline(a), Stroke.from_polyline(b)), SIZE, SIZE, unit="px", stroke_width=width)
    result = vectorize_image(render(drawing), VectorizeOptions(classifier="geometric", multi=True, seed=0))
    assert result.report.strokes == 2
    assert result.report.intersections == 1
    assert len(_crossings(result.drawing)) == 1


def test_retraced_runs_pair_a_spike_out_and_back_and_a_path_drawn_twice():
    # Branches 1, 2 out and back (a spike of two branches); 5 drawn twice the same way.
    branches = [0, 1, 2, 2, 1, 3, 5, 4, 5, 6]
    starts = ["a", "a", "a", "b", "b", "a", "a", "a", "a", "a"]
    assert retraced_runs(branches, starts) == [((1, 2), (3, 4), True), ((6, 6), (8, 8), False)]


def test_a_twin_cut_short_at_a_turn_keeps_what_both_passes_still_share():
    # Out along points 0-9 and back: the way back was cut where two branches part (its points
    # 3, 2, 1 left out, `half_turns`), so it meets the way out only from its two ends on.
    out = np.c_[np.arange(10.0), np.arange(10.0) ** 1.5]
    back = np.r_[out[::-1][:6], out[::-1][9:]]  # points 9..4, then 0
    xy = np.r_[out, back]
    twin = Twin((0, 9), (10, 16), True)
    assert not valid_twins(xy, [twin])
    parts = trimmed_twins(xy, [twin], [15])
    assert parts == [Twin((4, 9), (10, 15), True)]  # point 0 alone is no stretch
    assert valid_twins(xy, parts) == parts
    # A twin over no cut is left to `valid_twins` as it is.
    assert trimmed_twins(xy, [twin], [30]) == [twin]
