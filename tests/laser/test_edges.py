"""Edge cases of the laser planner: empty, zero-length, tiny, huge, many strokes, one point off."""

from __future__ import annotations

import numpy as np
import pytest

from tests.laser.gcode_read import grbl_refusals, parse_gcode
from fabrication.laser.gcode_write import GcodeOptions, gcode_lines
from machines.job_time import estimate_job_time as estimate_gcode_time
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from machines.laser_profile import load_laser_profile
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

PROFILE = load_laser_profile()


def _drawing(*polylines, size=100.0):
    return Drawing(tuple(Stroke.from_polyline(np.asarray(p, dtype=float)) for p in polylines), size, size, "px")


def _plan(drawing, **kw):
    kw.setdefault("placement", PlacementOptions(size=50))
    return plan_toolpath(drawing, PROFILE, ToolpathOptions(**kw))


def test_empty_drawing():
    with pytest.raises(InputError, match="no strokes"):
        _plan(Drawing((), 10, 10, "px"))


def test_only_zero_length_strokes():
    point = Stroke(np.zeros((1, 4, 2)) + 5.0)
    with pytest.raises(InputError):
        _plan(Drawing((point,), 10, 10, "px"), placement=PlacementOptions())


def test_zero_length_stroke_among_others_is_dropped():
    point = Stroke(np.zeros((1, 4, 2)) + 5.0)
    line = Stroke.from_polyline(np.array([[0.0, 0.0], [80.0, 0.0], [80.0, 30.0]]))
    tp = _plan(Drawing((point, line), 100, 100, "px"), placement=PlacementOptions())
    assert tp.dropped == 1 and len(tp.paths) == 1


@pytest.mark.parametrize("size", [0.1, 1.0, 399.9])  # from the smallest --size on
def test_tiny_and_bed_sized_designs(size):
    tp = _plan(_drawing([[0, 0], [100, 40], [30, 90]]), placement=PlacementOptions(size=size))
    lines = gcode_lines(tp, PROFILE, GcodeOptions())
    assert grbl_refusals(lines) == []
    moves = parse_gcode(lines)
    burn = np.vstack([moves.start[moves.laser_on], moves.end[moves.laser_on]])
    assert np.ptp(burn, axis=0).max() == pytest.approx(size, abs=0.002)


def test_three_hundred_strokes():
    rng = np.random.default_rng(3)
    polylines = [rng.uniform(0, 100, (2, 2)) for _ in range(300)]
    tp = _plan(_drawing(*polylines))
    assert len(tp.paths) == 300 and tp.travel_after < tp.travel_greedy <= tp.travel_before
    lines = gcode_lines(tp, PROFILE, GcodeOptions(passes=2))
    assert grbl_refusals(lines) == []
    assert estimate_gcode_time(lines, PROFILE).total_seconds > 0


def test_straight_stroke_becomes_one_move():
    tp = _plan(_drawing([[0, 0], [25, 25], [50, 50], [100, 100]]))
    assert tp.segment_count == 1


def test_design_exactly_at_the_bed_edge_and_one_step_over():
    _plan(_drawing([[0, 0], [100, 100]]), placement=PlacementOptions(size=400.0))
    with pytest.raises(InputError, match="does not fit"):
        _plan(_drawing([[0, 0], [100, 100]]), placement=PlacementOptions(size=400.01))
