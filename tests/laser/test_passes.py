"""Laser passes are read once: the job-time estimate and the player's data of a job with N
passes come from reading two periods of passes and extending them (`machines.job_repeat`),
and equal the reading of every line: the same seconds (to float rounding), the same moves
and chords, the same lines sent."""

from __future__ import annotations

import numpy as np
import pytest

from fabrication.job_options import laser_settings
from fabrication.laser.gcode_write import gcode_parts
from fabrication.laser.program import laser_program
from fabrication.laser.toolpath import plan_toolpath
from fabrication.player import gcode_player_data, laser_program_player_data
from machines.gcode_program import analyze_program
from machines.grbl_settings import settings_from_profile
from machines.job_repeat import RepeatedLines, read_repeated
from machines.job_time import estimate_program_time
from machines.laser_profile import LaserProfile
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _drawing() -> Drawing:
    t = np.linspace(0.0, 2.0 * np.pi, 300)
    loop = Stroke.from_polyline(np.c_[100 + 60 * np.cos(t), 100 + 40 * np.sin(3 * t)])
    wave = Stroke.from_polyline(np.c_[np.linspace(20, 180, 200), 170 + 8 * np.sin(np.linspace(0, 12, 200))])
    return Drawing((loop, wave), 200.0, 200.0, "px", 4.0)


def _job(drawing, profile=None, **options) -> RepeatedLines:
    settings = laser_settings(profile=profile, **options)
    toolpath = plan_toolpath(drawing, settings.profile, settings.toolpath)
    head, body, count, tail = gcode_parts(toolpath, settings.profile, settings.gcode).repeated()
    return RepeatedLines(head=tuple(head), body=tuple(body), count=count, tail=tuple(tail), first_line=6)


def _every_line(job: RepeatedLines, profile: LaserProfile):
    program = job.program()
    stats = analyze_program(program, settings=settings_from_profile(profile), planner_blocks=profile.planner_blocks,
                            allow_settings=False)
    return program, stats, estimate_program_time(program, profile, stats=stats)


DEFAULT = LaserProfile()
JOBS = [  # (profile, options): planner-bound and link-bound, lines and arcs, odd and even passes
    (DEFAULT, dict(size="80mm", passes=7)),
    (DEFAULT, dict(size="150mm", passes=20, tolerance="0.005mm", return_home=True)),
    (DEFAULT, dict(size="60mm", passes=12, arcs=True, feed="3000mm/min")),
    (LaserProfile(baud=9600), dict(size="60mm", passes=12, tolerance="0.005mm", feed="6000mm/min")),
    (LaserProfile(parse_time=0.01, acceleration_x=3000, acceleration_y=3000),
     dict(size="60mm", passes=8, tolerance="0.005mm", feed="6000mm/min")),
    (LaserProfile(planner_blocks=35, rx_buffer=1024), dict(size="100mm", passes=11, air_assist=True)),
    (LaserProfile(planner_blocks=4, rx_buffer=16), dict(size="60mm", passes=10, arcs=True)),
]


@pytest.mark.parametrize("profile,options", JOBS, ids=[f"{p.baud}-{p.planner_blocks}-{o}" for p, o in JOBS])
def test_passes_read_twice_and_extended_equal_every_line_read(profile, options):
    job = _job(_drawing(), profile, **options)
    fast = read_repeated(job, profile)
    assert fast.extended, "the two-period reading should have been extended"
    program, stats, full = _every_line(job, profile)
    assert fast.sent == len(program)
    time = fast.time
    # the same seconds: float rounding apart (about 1e-12 s here; 1e-6 s per period is the
    # check's own tolerance)
    for name in ("total_seconds", "planner_seconds", "link_seconds", "burn_seconds", "travel_seconds",
                 "burn_length", "travel_length", "naive_seconds"):
        assert getattr(time, name) == pytest.approx(getattr(full, name), abs=1e-6 * job.count), name
    assert (time.bound, time.blocks, time.errors) == (full.bound, full.blocks, full.errors)
    assert np.array_equal(time.block_line, full.block_line)
    assert np.allclose(time.block_seconds, full.block_seconds, rtol=0, atol=1e-9)
    # per line: where the link model branches on two equal times (a block planned just as
    # another ends), rounding may take the other branch for a few lines (measured: at most
    # 7 ms, on a link-bound job), and the times meet again
    assert len(time.line_seconds) == len(full.line_seconds)
    assert np.abs(time.line_seconds - full.line_seconds).max() < 0.05
    # the same moves and chords, lines and flags
    for name in ("start", "end", "feed", "rapid", "stop_before", "move", "index"):
        assert np.array_equal(getattr(fast.stats.segments, name), getattr(stats.segments, name), equal_nan=True), name
    for name in ("kind", "start", "end", "centre", "feed", "power", "laser_on", "line"):
        assert np.array_equal(getattr(fast.stats.moves, name), getattr(stats.moves, name), equal_nan=True), name
    assert np.array_equal(fast.stats.syncs, stats.syncs) and np.array_equal(fast.stats.dwell, stats.dwell)
    assert np.allclose(fast.stats.line_seconds, stats.line_seconds, rtol=0, atol=1e-6)
    assert (fast.stats.extent, fast.stats.burn_extent, fast.stats.max_s) == (stats.extent, stats.burn_extent,
                                                                             stats.max_s)


def test_a_body_shorter_than_the_planner_is_read_whole():
    """A pass of fewer blocks than the planner holds: the state at a period's start reaches
    back over more than a period, so nothing is extended: every line is read."""
    line = Stroke.from_polyline(np.array([[20.0, 20.0], [60.0, 25.0], [90.0, 70.0]]))
    job = _job(Drawing((line,), 100.0, 100.0, "px", 2.0), DEFAULT, size="30mm", passes=9)
    fast = read_repeated(job, DEFAULT)
    assert not fast.extended
    _, _, full = _every_line(job, DEFAULT)
    assert fast.time.total_seconds == full.total_seconds
    assert np.array_equal(fast.time.line_seconds, full.line_seconds)


@pytest.mark.parametrize("passes", range(1, 9))
def test_the_repeated_parts_are_the_lines_written(passes):
    settings = laser_settings(size="50mm", passes=passes, return_home=True)
    toolpath = plan_toolpath(_drawing(), settings.profile, settings.toolpath)
    parts = gcode_parts(toolpath, settings.profile, settings.gcode)
    head, body, count, tail = parts.repeated()
    assert head + body * count + tail == parts.lines()
    assert count == max(0, (passes - 1) // 2)
    # passes alternate direction, each (after the first) starting where the last ended
    assert len({id(lines) for lines in parts.passes}) == min(passes, 3)


def test_the_players_data_of_many_passes_is_that_of_every_line_read():
    settings = laser_settings(size="60mm", passes=15)
    program = laser_program(_drawing(), settings.profile, settings.toolpath, settings.gcode, name="loops.png")
    again = gcode_player_data(program.lines, title="t", profile=settings.profile)
    reused = laser_program_player_data(program, title="t", profile=settings.profile)
    assert np.array_equal(again.points, reused.points) and np.array_equal(again.kinds, reused.kinds)
    assert np.array_equal(again.numbers, reused.numbers) and np.array_equal(again.colors, reused.colors)
    assert np.allclose(again.times, reused.times, rtol=0, atol=1e-6)
    assert again.total == pytest.approx(reused.total, abs=1e-6)
    assert program.sent == len(program.lines) - 5  # every line but the header's comments
