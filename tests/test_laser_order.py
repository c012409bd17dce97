"""Stroke order and direction: greedy + 2-opt never worse than the drawing's order; deterministic."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.laser.travel_order import order_strokes, travel_length
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import hershey_text_drawing
from machines.laser_profile import load_laser_profile


def _oriented(starts, ends, result):
    s = np.where(result.flipped[:, None], ends[result.order], starts[result.order])
    e = np.where(result.flipped[:, None], starts[result.order], ends[result.order])
    return s, e


def _brute_force(starts, ends):
    n = len(starts)
    best = np.inf
    for perm in itertools.permutations(range(n)):
        for flips in itertools.product((False, True), repeat=n):
            f = np.array(flips)
            s = np.where(f[:, None], ends[list(perm)], starts[list(perm)])
            e = np.where(f[:, None], starts[list(perm)], ends[list(perm)])
            best = min(best, travel_length(s, e, np.zeros(2)))
    return best


@pytest.mark.parametrize("seed", range(6))
def test_small_cases_near_optimal(seed):
    rng = np.random.default_rng(seed)
    starts = rng.uniform(0, 100, (5, 2))
    ends = starts + rng.normal(0, 20, (5, 2))
    result = order_strokes(starts, ends)
    assert sorted(result.order.tolist()) == list(range(5))
    s, e = _oriented(starts, ends, result)
    assert travel_length(s, e, np.zeros(2)) == pytest.approx(result.after)
    assert result.after <= result.greedy + 1e-9 and result.after <= result.before + 1e-9
    optimum = _brute_force(starts, ends)
    assert result.after <= 1.25 * optimum + 1e-9


def test_many_strokes_improve_a_lot_and_are_deterministic():
    rng = np.random.default_rng(7)
    starts = rng.uniform(0, 300, (400, 2))
    ends = starts + rng.normal(0, 5, (400, 2))
    a = order_strokes(starts, ends)
    b = order_strokes(starts, ends)
    assert np.array_equal(a.order, b.order) and np.array_equal(a.flipped, b.flipped)
    assert a.after < 0.1 * a.before
    assert a.after < 0.95 * a.greedy  # 2-opt does real work after the greedy start


def test_single_stroke_is_turned_to_start_near_the_head():
    result = order_strokes(np.array([[100.0, 100.0]]), np.array([[1.0, 1.0]]))
    assert result.flipped.tolist() == [True] and result.after == pytest.approx(np.hypot(1, 1))


def test_planner_reports_travel_and_keep_order():
    profile = load_laser_profile()
    drawing = hershey_text_drawing("onestroke")
    placement = PlacementOptions(size=100)
    optimized = plan_toolpath(drawing, profile, ToolpathOptions(placement=placement))
    kept = plan_toolpath(drawing, profile, ToolpathOptions(placement=placement, optimize=False))
    assert optimized.travel_after < optimized.travel_before
    assert kept.travel_after == pytest.approx(kept.travel_before) == pytest.approx(optimized.travel_before)
    assert optimized.burn_length == pytest.approx(kept.burn_length)
    # the paths' own travel agrees with the report
    starts = np.array([p.points[0] for p in optimized.paths])
    ends = np.array([p.points[-1] for p in optimized.paths])
    assert travel_length(starts, ends, np.zeros(2)) == pytest.approx(optimized.travel_after)
