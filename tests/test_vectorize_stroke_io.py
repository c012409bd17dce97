"""`Stroke` geometry and the SVG / JSON round trips of a `Drawing`."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke
from vectorize.svg.svg_read import read_svg
from vectorize.svg_write import drawing_from_json, drawing_to_json, drawing_to_svg, write_drawing


def wavy() -> Stroke:
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(0, 30, (9, 2)), axis=0) + 200
    control = []
    for a, b in zip(pts[:-1], pts[1:]):
        control.append([a, a + rng.normal(0, 20, 2), b + rng.normal(0, 20, 2), b])
    # Make it G1 at the joints so it looks like a fitted curve.
    control = np.array(control)
    for k in range(1, len(control)):
        control[k, 1] = control[k, 0] + (control[k - 1, 3] - control[k - 1, 2])
    return Stroke(control)


def test_length_and_even_sampling():
    square = Stroke.from_polyline(np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0.0]]))
    assert square.length == pytest.approx(40.0)
    assert square.is_closed
    pts = square.sample_evenly(3.0)
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert len(pts) == 15 and np.allclose(pts[0], pts[-1])
    assert np.allclose(square.points_at_lengths([0, 5, 15, 40]), [[0, 0], [5, 0], [10, 5], [0, 0]])
    assert steps.max() <= 40 / 14 + 1e-9


@pytest.mark.parametrize("tolerance", [1.0, 0.1, 0.02])
def test_flatten_stays_within_tolerance(tolerance):
    stroke = wavy()
    polyline = stroke.flatten(tolerance)
    dense = stroke.points_at(np.linspace(0, 1, 200_000))
    # Distance from every curve point to the polyline's segments.
    from shapely import LineString, distance, points

    line = LineString(polyline)
    assert distance(points(dense), line).max() <= tolerance * 1.0001
    assert np.allclose(polyline[0], stroke.start) and np.allclose(polyline[-1], stroke.end)


def test_reversal_and_transform():
    stroke = wavy()
    back = stroke.reversed()
    assert np.allclose(back.start, stroke.end) and back.length == pytest.approx(stroke.length)
    assert np.allclose(back.points_at(0.3), stroke.points_at(0.7))
    moved = stroke.transformed(np.array([[2.0, 0, 5], [0, 2.0, -1]]))
    assert moved.length == pytest.approx(2 * stroke.length)
    with pytest.raises(InputError):
        Stroke(np.zeros((2, 3, 2)))


def test_svg_round_trip(tmp_path):
    drawing = Drawing((wavy(), wavy().reversed()), 640, 480, "px", 4.5)
    path = tmp_path / "d.svg"
    write_drawing(drawing, path)
    content = read_svg(path)
    assert (content.width, content.height) == (640, 480)
    assert content.stroke_width == pytest.approx(4.5)
    assert len(content.strokes) == 2
    for original, parsed in zip(drawing.strokes, content.strokes):
        assert np.abs(original.control - parsed.control).max() < 1e-3
    text = path.read_text()
    assert text.count("<path") == 2 and 'viewBox="0 0 640 480"' in text


def test_json_round_trip(tmp_path):
    drawing = Drawing((wavy(),), 300, 200, "px", 3.0)
    path = tmp_path / "d.json"
    write_drawing(drawing, path)
    back = drawing_from_json(path.read_text())
    assert back.width == 300 and back.height == 200 and back.stroke_width == 3.0
    assert np.abs(back.strokes[0].control - drawing.strokes[0].control).max() < 1e-4
    assert drawing_to_json(drawing) == drawing_to_json(back)
    with pytest.raises(InputError):
        drawing_from_json('{"format": "other"}')


def test_svg_text_is_deterministic():
    drawing = Drawing((wavy(),), 300, 200)
    assert drawing_to_svg(drawing) == drawing_to_svg(Drawing((wavy(),), 300, 200))


def test_closed_path_survives_round_trip(tmp_path):
    t = np.linspace(0, 2 * np.pi, 50)
    ring = Stroke.from_polyline(np.c_[100 + 50 * np.cos(t), 100 + 50 * np.sin(t)])
    path = tmp_path / "ring.svg"
    write_drawing(Drawing((ring,), 200, 200), path)
    parsed = read_svg(path).strokes[0]
    assert parsed.is_closed
    assert cKDTree(ring.sample_evenly(1)).query(parsed.sample_evenly(1))[0].max() < 1e-2


def test_bounds_are_exact():
    stroke = wavy()
    dense = stroke.points_at(np.linspace(0, 1, 400_001))
    expected = (*dense.min(axis=0), *dense.max(axis=0))
    assert np.allclose(stroke.bounds(), expected, atol=1e-6)
    line = Stroke.from_polyline(np.array([[0.0, 5.0], [10.0, 5.0]]))
    assert np.allclose(line.bounds(), (0, 5, 10, 5))
