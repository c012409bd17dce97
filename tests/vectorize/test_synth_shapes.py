"""The crossing classifier's training data holds the shapes of cursive handwriting: loops that
cross themselves, strokes bending at a crossing, branches ending just past a junction."""

from __future__ import annotations

import numpy as np
import shapely

from vectorize.training.synth import (SHAPES, _bent_through, _curve, _cursive_branches, _cut_branch,
                                      _loop_crossing, generate)

W, STEP = 3.0, 0.3


def _turn_deg(points: np.ndarray) -> float:
    """Total change of heading (degrees) along a polyline."""
    heading = np.unwrap(np.arctan2(*np.diff(points, axis=0).T[::-1]))
    return float(np.degrees(abs(heading[-1] - heading[0])))


def _winding_deg(points: np.ndarray) -> float:
    """Sum of the absolute heading changes (degrees) along a polyline."""
    heading = np.unwrap(np.arctan2(*np.diff(points, axis=0).T[::-1]))
    return float(np.degrees(np.abs(np.diff(heading)).sum()))


def test_a_loop_crosses_itself_once_at_the_origin():
    rng = np.random.default_rng(11)
    loops = [loop for loop in (_loop_crossing(rng, W, STEP) for _ in range(40)) if loop is not None]
    assert len(loops) >= 20
    for points, first, last, angle in loops:
        line = shapely.LineString(points)
        assert not line.is_simple
        # Noding the line splits it at its self-crossing: one crossing gives three pieces.
        pieces = shapely.get_parts(shapely.node(line))
        assert len(pieces) == 3
        crossing = shapely.get_point(pieces[1], 0)
        assert np.hypot(shapely.get_x(crossing), shapely.get_y(crossing)) < STEP
        assert 15.0 <= angle <= 90.0
        loop_length = (last - first) * STEP
        assert 4.0 * W < loop_length <= 60.0 * W
        assert _turn_deg(points[first:last + 1]) > 180.0  # a loop, not a wiggle


def test_a_bent_stroke_crosses_the_other_once_and_bends_near_the_crossing():
    rng = np.random.default_rng(12)
    made = 0
    for _ in range(40):
        a = np.radians(rng.uniform(15.0, 90.0))
        curves = [_curve(rng, np.zeros(2), -a / 2, 0.0, W, STEP), _curve(rng, np.zeros(2), a / 2, 0.0, W, STEP)]
        bent = _bent_through(rng, a, W, STEP, curves)
        if bent is None:
            continue
        made += 1
        (one, two), angle = bent
        assert angle >= 15.0
        meet = shapely.LineString(one).intersection(shapely.LineString(two))
        assert meet.geom_type == "Point" and np.hypot(meet.x, meet.y) < STEP
        changed = one if not np.array_equal(one, curves[0]) else two
        near = changed[np.hypot(changed[:, 0], changed[:, 1]) < 5.0 * W]
        assert _turn_deg(near) >= 10.0  # the bend lies within a few widths of the crossing
    assert made >= 20


def test_a_short_branch_ends_the_asked_distance_past_the_junction():
    rng = np.random.default_rng(13)
    stroke = _curve(rng, np.zeros(2), 0.3, 0.0, W, STEP)
    at = len(stroke) // 2
    for _ in range(10):
        cut, widths = _cut_branch(rng, stroke, np.full(len(stroke), W), (at, at), 4.0 * W, STEP)
        assert len(cut) == len(widths)
        arc = np.hypot(*np.diff(cut, axis=0).T).sum()
        assert abs(arc - (30.0 * W + 4.0 * W)) < 2 * STEP  # the other branch keeps its 30 w


def test_cursive_branches_curl_away_from_the_junction_and_leave_it_as_it_was():
    rng = np.random.default_rng(14)
    stroke = _curve(rng, np.zeros(2), 0.4, 0.0, W, STEP)
    at = len(stroke) // 2
    calm = 5.0 * W
    curled = 0
    for _ in range(10):
        out = _cursive_branches(rng, stroke, (at, at), calm, W, STEP, np.zeros(2))
        near = slice(at - int(calm / STEP), at + int(calm / STEP) + 1)
        assert np.allclose(out[near], stroke[near])
        assert np.allclose(np.hypot(*np.diff(out, axis=0).T), STEP)  # still evenly spaced
        if not np.allclose(out, stroke):
            curled += 1
            beyond = np.r_[np.arange(near.start), np.arange(near.stop, len(out))]
            assert np.min(np.hypot(*out[beyond].T)) >= 2.5 * W
            # curvature bumps of radius 1.5-6 w: far more turning than the gentle original
            assert _winding_deg(out) > _winding_deg(stroke) + 90.0
    assert curled >= 5


def test_generated_data_holds_every_shape_with_the_right_labels():
    data = generate(256, seed=5)
    assert data.shape.shape == data.label.shape
    seen = {name: data.label[data.shape == i] for i, name in enumerate(SHAPES)}
    assert all(len(labels) > 0 for labels in seen.values()), {k: len(v) for k, v in seen.items()}
    assert np.all(seen["loop_crossing"] == 1) and np.all(seen["bent_crossing"] == 1)
    assert set(seen["short_branch"].tolist()) == {0, 1}
    assert np.all(data.angle[data.shape == SHAPES.index("loop_crossing")] >= 15.0)
    assert set(data.label[data.context].tolist()) == {0, 1} and 0.2 < data.context.mean() < 0.5
    prefix = generate(8, seed=5)  # the first chunk's seed makes its first samples
    assert np.array_equal(prefix.x, data.x[:8]) and np.array_equal(prefix.shape, data.shape[:8])
    assert np.array_equal(prefix.context, data.context[:8])
