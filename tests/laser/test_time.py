"""The job-time estimate agrees with an independent GRBL planner simulation within 2 %."""

from __future__ import annotations

import numpy as np
import pytest

from fabrication.laser.gcode_write import GcodeOptions, gcode_lines
from machines.job_time import estimate_job_time as estimate_gcode_time
from machines.job_time import format_duration
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import spiral_job, straight_line_job, trefoil_png
from benchmarks.metrics.grbl_sim import simulate
from machines.laser_profile import LaserProfile, load_laser_profile

PROFILE = load_laser_profile()


def _sim(lines, profile=PROFILE):
    return simulate(lines, max_rate=(profile.max_rate_x, profile.max_rate_y),
                    accel=(profile.acceleration_x, profile.acceleration_y),
                    junction_deviation=profile.junction_deviation, arc_tolerance=profile.arc_tolerance,
                    steps_per_mm=(profile.steps_per_mm_x, profile.steps_per_mm_y),
                    planner_blocks=profile.planner_blocks)


@pytest.fixture(scope="module")
def vectorized_lines(tmp_path_factory):
    from vectorize import VectorizeOptions, vectorize_file

    png = trefoil_png(tmp_path_factory.mktemp("png") / "trefoil.png")
    drawing = vectorize_file(png, VectorizeOptions(classifier="geometric")).drawing
    out = {}
    for arcs in (False, True):
        tp = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=60), arcs=arcs))
        out[arcs] = gcode_lines(tp, PROFILE, GcodeOptions(feed=3000.0, passes=2))
    small = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=20)))
    out["small"] = gcode_lines(small, PROFILE, GcodeOptions(feed=6000.0))
    return out


def _compare(lines, label):
    job = estimate_gcode_time(lines, PROFILE)
    sim = _sim(lines)
    error = job.total_seconds / sim - 1
    naive_error = job.naive_seconds / sim - 1
    print(f"{label}: estimate {job.total_seconds:.3f} s, simulation {sim:.3f} s ({error:+.2%}), "
          f"length/feed {job.naive_seconds:.3f} s ({naive_error:+.1%})")
    assert abs(error) <= 0.02
    return job, sim


@pytest.mark.parametrize("feed", [1500.0, 6000.0])
def test_long_straight_line(feed):
    job, sim = _compare(straight_line_job(feed), f"straight line F{feed:g}")
    # by hand: one trapezoid over 537.4 mm from rest to rest
    length = np.hypot(380, 380)
    v = feed / 60
    accel = PROFILE.acceleration_x * np.sqrt(2)  # GRBL's per-axis limit on a diagonal
    burn = length / v + v / accel
    assert job.burn_seconds == pytest.approx(burn, rel=1e-3)


@pytest.mark.parametrize("feed", [1500.0, 3000.0, 6000.0])
def test_spiral_of_short_segments(feed):
    job, sim = _compare(spiral_job(feed), f"spiral of 0.05 mm segments F{feed:g}")
    if feed >= 3000:
        # the planner, not the feed, limits dense work: length/feed is far too low
        assert job.naive_seconds < 0.8 * sim


@pytest.mark.parametrize("arcs", [False, True])
def test_vectorized_drawing(vectorized_lines, arcs):
    _compare(vectorized_lines[arcs], f"vectorized trefoil, {'arcs' if arcs else 'lines'}, F3000, 2 passes")


def test_small_fast_vectorized_drawing(vectorized_lines):
    # 20 mm at F6000: corners and look-ahead, not the feed, set the pace
    job, sim = _compare(vectorized_lines["small"], "vectorized trefoil 20 mm, lines, F6000")
    assert job.naive_seconds < 0.8 * sim


def test_forced_stops_are_modelled():
    # the same two strokes with an M5/M4 pair between them: GRBL stops there
    smooth = ["G21", "G90", "M4S0", "G0X0Y0", "G1X50S500F3000", "G1X100", "M5"]
    stopped = ["G21", "G90", "M4S0", "G0X0Y0", "G1X50S500F3000", "M5", "M4", "G1X100", "M5"]
    a, b = estimate_gcode_time(smooth, PROFILE), estimate_gcode_time(stopped, PROFILE)
    assert b.total_seconds > a.total_seconds + 0.05
    assert b.total_seconds == pytest.approx(_sim(stopped), rel=0.02)
    dwell = estimate_gcode_time(smooth[:-1] + ["G4P1.5", "M5"], PROFILE, link=False)
    assert dwell.total_seconds == pytest.approx(a.planner_seconds + 1.5, abs=1e-9)
    # through the link, the dwell line is parsed once the planner has drained: one parse more
    linked = estimate_gcode_time(smooth[:-1] + ["G4P1.5", "M5"], PROFILE)
    assert linked.total_seconds == pytest.approx(a.total_seconds + 1.5 + PROFILE.parse_time, abs=1e-3)


@pytest.mark.parametrize("between,same_without_stop,stops", [
    (["G1X60S300"], ["G1X60"], False),                # S change on a moving G1: laser mode keeps going
    (["G0X60S300", "G1X70"], ["G0X60", "G1X70"], False),  # ... on a moving G0 too (any line with axes)
    (["S300"], [], True),                            # S change on a line that does not move
    (["M8"], [], True),                              # coolant (air assist) change
    (["M4"], [], False),                             # spindle state unchanged: no stop
    (["G4P0"], [], True),                            # dwell
])
def test_what_forces_a_stop(between, same_without_stop, stops):
    base = ["G21", "G90", "M4S0", "G0X0Y0", "G1X50S500F3000"]
    after = ["G1X100Y0", "M5"]
    smooth = estimate_gcode_time(base + same_without_stop + after, PROFILE)
    job = estimate_gcode_time(base + between + after, PROFILE)
    assert (job.total_seconds > smooth.total_seconds + 0.02) == stops
    assert job.total_seconds == pytest.approx(_sim(base + between + after), rel=0.02)


def test_m3_mode_switch_without_motion_stops():
    base = ["G21", "G90", "M3S500", "G1X50F3000", "G1X60"]
    plain = estimate_gcode_time(base + ["G1X100", "M5"], PROFILE)
    switched = estimate_gcode_time(base + ["G0", "G1X100", "M5"], PROFILE)
    assert switched.total_seconds > plain.total_seconds + 0.02
    assert switched.total_seconds == pytest.approx(_sim(base + ["G0", "G1X100", "M5"]), rel=0.02)


def test_per_line_seconds_are_cumulative():
    lines = spiral_job(3000.0)
    job = estimate_gcode_time(lines, PROFILE)
    assert len(job.line_seconds) == len(lines)
    assert np.all(np.diff(job.line_seconds) >= 0)
    assert job.line_seconds[-1] == pytest.approx(job.total_seconds)
    # the G0 comes first; through the link it starts once 4 lines have been sent and parsed
    assert job.line_seconds[3] == pytest.approx(job.travel_seconds, abs=4 * PROFILE.parse_time + 0.002)
    planner_only = estimate_gcode_time(lines, PROFILE, link=False)
    assert planner_only.line_seconds[3] == pytest.approx(planner_only.travel_seconds)
    assert planner_only.line_seconds[2] == 0.0


def test_slower_machine_takes_longer():
    slow = LaserProfile(acceleration_x=100.0, acceleration_y=100.0)
    lines = spiral_job(3000.0)
    assert estimate_gcode_time(lines, slow).total_seconds > 1.2 * estimate_gcode_time(lines, PROFILE).total_seconds


def test_format_duration():
    assert format_duration(12.34) == "12.3 s"
    assert format_duration(125) == "2:05"
    assert format_duration(3723) == "1:02:03"
