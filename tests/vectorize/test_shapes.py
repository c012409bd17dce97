"""The pipeline on small constructed drawings whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from tests.drawings import alpha_loop, circle, figure_eight, render_polylines, v_spike
from vectorize import VectorizeOptions, vectorize_image

GEOMETRIC = VectorizeOptions(classifier="geometric")


def _max_turn_degrees(stroke, step=2.0, skip_near=None, radius=0.0):
    """Largest change of direction between consecutive chords of `step` px."""
    pts = stroke.sample_evenly(step)
    d = np.diff(pts, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    cos = np.clip((d[1:] * d[:-1]).sum(1), -1, 1)
    angles = np.degrees(np.arccos(cos))
    if skip_near is not None:
        far = np.linalg.norm(pts[1:-1] - skip_near, axis=1) > radius
        angles = angles[far]
    return float(angles.max())


def _distance_to(points, reference):
    """Distance from each point to the polyline `reference` (densified to 0.05 px)."""
    from scipy.spatial import cKDTree

    from vectorize.stroke import Stroke

    dense = Stroke.from_polyline(reference).sample_evenly(0.05)
    return cKDTree(dense).query(points)[0]


def test_circle_is_one_closed_stroke():
    truth = circle()
    result = vectorize_image(render_polylines([truth]), GEOMETRIC)
    assert result.report.strokes == 1
    stroke = result.drawing.strokes[0]
    assert stroke.is_closed
    assert stroke.length == pytest.approx(2 * np.pi * 120, rel=0.01)
    assert _distance_to(stroke.sample_evenly(2.0), truth).max() < 1.0
    assert result.drawing.stroke_width == pytest.approx(6.0, abs=1.2)


@pytest.mark.parametrize("classifier", ["geometric", "cnn"])
def test_figure_eight_goes_straight_through_its_crossing(classifier):
    truth = figure_eight()
    result = vectorize_image(render_polylines([truth]), VectorizeOptions(classifier=classifier))
    assert result.report.strokes == 1
    assert result.report.intersections == 1
    stroke = result.drawing.strokes[0]
    assert stroke.is_closed
    # Within a fifth of the stroke width everywhere, the crossing included.
    assert _distance_to(stroke.sample_evenly(2.0), truth).max() < 1.2
    # Straight through: no sharp turn anywhere, the crossing included.
    assert _max_turn_degrees(stroke) < 20.0


@pytest.mark.parametrize("classifier", ["geometric", "cnn"])
def test_alpha_loop_is_one_open_stroke_through_the_crossing(classifier):
    truth = alpha_loop()
    result = vectorize_image(render_polylines([truth]), VectorizeOptions(classifier=classifier))
    assert result.report.strokes == 1
    assert result.report.intersections == 1
    stroke = result.drawing.strokes[0]
    assert not stroke.is_closed
    ends = {tuple(np.round(stroke.start)), tuple(np.round(stroke.end))}
    for end in (truth[0], truth[-1]):
        assert min(np.linalg.norm(np.array(e) - end) for e in ends) < 4.0
    assert _max_turn_degrees(stroke) < 20.0
    assert stroke.length == pytest.approx(np.linalg.norm(np.diff(truth, axis=0), axis=1).sum(), rel=0.02)


@pytest.mark.parametrize("width", [1.2, 25.0, 40.0])
def test_thin_and_marker_thick_lines_keep_their_ends(width):
    """A 1.2 px pen line and a marker 25-40 px wide (tails 3-5 widths long): the ragged outline
    of thick ink grows many spurs; pruning them must not eat the tails."""
    truth = alpha_loop()
    result = vectorize_image(render_polylines([truth], width=width), VectorizeOptions(seed=0))
    assert result.report.strokes == 1 and result.report.intersections == 1
    stroke = result.drawing.strokes[0]
    assert stroke.length == pytest.approx(np.linalg.norm(np.diff(truth, axis=0), axis=1).sum(), rel=0.02)
    for end in (truth[0], truth[-1]):
        assert min(np.linalg.norm(e - end) for e in (stroke.start, stroke.end)) < max(4.0, width / 4)


def test_v_spike_is_one_stroke_out_and_back():
    truth = v_spike()
    result = vectorize_image(render_polylines([truth]), GEOMETRIC)
    assert result.report.strokes == 1
    assert result.report.y_junctions == 1
    stroke = result.drawing.strokes[0]
    # Starts and ends at the two free ends, reaches the tip in between.
    assert np.linalg.norm(stroke.start - truth[0]) < 4.0
    assert np.linalg.norm(stroke.end - truth[2]) < 4.0
    tip_distance = _distance_to(truth[1:2], stroke.sample_evenly(1.0))[0]
    assert tip_distance < 4.0
    true_length = np.linalg.norm(np.diff(truth, axis=0), axis=1).sum()
    assert stroke.length == pytest.approx(true_length, rel=0.03)


def test_two_strokes_in_multi_mode_are_two_strokes():
    lines = [np.array([[50.0, 100.0], [350.0, 120.0]]), np.array([[60.0, 300.0], [340.0, 280.0]])]
    image = render_polylines(lines)
    multi = vectorize_image(image, VectorizeOptions(multi=True, classifier="geometric"))
    assert multi.report.strokes == 2
    for stroke in multi.drawing.strokes:
        assert min(_distance_to(stroke.sample_evenly(2.0), line_pts).max()
                   for line_pts in (np.linspace(*lines[0], 200), np.linspace(*lines[1], 200))) < 1.0
    single = vectorize_image(image, GEOMETRIC)
    assert single.report.strokes == 1
    assert single.report.dropped_components == 1
    assert any("dropped" in w for w in single.report.warnings)


def test_output_is_in_the_input_frame_when_downscaled():
    big = render_polylines([circle(cx=1000, cy=750, radius=500)], size=(2000, 1500), width=16)
    result = vectorize_image(big, GEOMETRIC)
    assert result.report.scale == pytest.approx(0.5)
    assert any("downscaled" in w for w in result.report.warnings)
    assert (result.drawing.width, result.drawing.height) == (2000, 1500)
    assert result.drawing.strokes[0].length == pytest.approx(2 * np.pi * 500, rel=0.01)
    assert result.drawing.stroke_width == pytest.approx(16, abs=3)


def test_same_input_same_svg_bytes():
    from vectorize.svg_write import drawing_to_svg

    image = render_polylines([alpha_loop()])
    first = drawing_to_svg(vectorize_image(image, VectorizeOptions()).drawing)
    second = drawing_to_svg(vectorize_image(image, VectorizeOptions()).drawing)
    assert first == second


@pytest.mark.parametrize("name, lines, lengths", [
    ("T", [[[80, 80], [320, 80]], [[200, 80], [200, 350]]], [240, 270]),
    ("A", [[[100, 350], [200, 50], [300, 350]], [[140, 230], [260, 230]]], [632, 120]),
    ("H", [[[100, 50], [100, 350]], [[300, 50], [300, 350]], [[100, 200], [300, 200]]], [300, 300, 200]),
])
def test_multi_mode_letters_keep_their_strokes(name, lines, lengths):
    image = render_polylines([np.array(line, dtype=float) for line in lines])
    result = vectorize_image(image, VectorizeOptions(multi=True, classifier="geometric"))
    assert result.report.intersections == 0  # T-junctions are stroke ends, never crossings
    found = sorted(s.length for s in result.drawing.strokes)
    assert len(found) == len(lengths)
    # A stroke ending on another line stops at that line's centre: up to half a width short.
    assert np.allclose(found, sorted(lengths), atol=6.0)


def _erase_disc(image: np.ndarray, centre, radius: float) -> np.ndarray:
    rows, cols = np.mgrid[0:image.shape[0], 0:image.shape[1]]
    out = image.copy()
    out[(cols + 0.5 - centre[0]) ** 2 + (rows + 0.5 - centre[1]) ** 2 <= radius ** 2] = 255
    return out


@pytest.mark.parametrize("where", [0.04, 0.5])  # on a tail (two pieces), on the loop (one piece)
def test_pen_gaps_are_bridged_in_single_line_mode(where):
    truth = alpha_loop()
    image = _erase_disc(render_polylines([truth]), truth[int(where * len(truth))], 7.0)
    result = vectorize_image(image, VectorizeOptions(seed=0))
    assert result.report.strokes == 1 and result.report.gaps_bridged == 1
    assert result.report.dropped_components == 0
    stroke = result.drawing.strokes[0]
    assert stroke.length == pytest.approx(np.linalg.norm(np.diff(truth, axis=0), axis=1).sum(), rel=0.03)
    assert _distance_to(stroke.sample_evenly(2.0), truth).max() < 2.0


def test_an_open_c_and_a_line_ending_beside_another_are_not_bridged():
    t = np.linspace(np.radians(20), np.radians(340), 300)
    c_shape = np.c_[200 + 120 * np.cos(t), 200 + 120 * np.sin(t)]  # ends 82 px apart, facing
    result = vectorize_image(render_polylines([c_shape], width=12.0), VectorizeOptions(seed=0))
    assert result.report.gaps_bridged == 0 and not result.drawing.strokes[0].is_closed
    # A stroke that stops 12 px short of the side of another: it points at no end.
    tee = [np.array([[60.0, 200.0], [340.0, 200.0]]), np.array([[200.0, 60.0], [200.0, 188.0]])]
    result = vectorize_image(render_polylines(tee, width=6.0), VectorizeOptions(seed=0))
    assert result.report.gaps_bridged == 0 and result.report.dropped_components == 1
    assert result.report.strokes == 1


def test_a_line_cut_off_at_a_corner_is_bridged_to_the_corner():
    # A "P" drawn in one stroke; a dry-pen break cuts the stem off just below the bowl's
    # corner. The far side of that gap is a corner of the other piece, not an end.
    truth = np.array([[100.0, 350.0], [100.0, 60.0], [300.0, 60.0], [300.0, 200.0], [100.0, 200.0]])
    image = render_polylines([truth], width=6.0).copy()
    image[205:209, 90:111] = 255
    result = vectorize_image(image, VectorizeOptions(seed=0))
    assert result.report.strokes == 1 and result.report.dropped_components == 0
    assert result.report.gaps_bridged == 1
    stroke = result.drawing.strokes[0]
    assert np.linalg.norm(stroke.sample_evenly(2.0) - truth[0], axis=1).min() < 6.0  # the stem's foot is drawn
    assert stroke.length == pytest.approx(np.linalg.norm(np.diff(truth, axis=0), axis=1).sum(), rel=0.03)
