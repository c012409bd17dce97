"""Every emitted line is valid GRBL 1.1 (strict parser), short, clean; stroke structure holds."""

from __future__ import annotations

import numpy as np
import pytest

from machines.framing import framing_lines
from laser_fixtures import grbl_refusals, parse_gcode
from machines.grbl_protocol import clean_line as strip_line
from fabrication.laser.gcode_write import GcodeOptions, fmt, gcode_lines, gcode_text
from machines.job_time import estimate_job_time as estimate_gcode_time
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import hershey_text_drawing, rose_drawing, wiggle_drawing
from machines.laser_profile import LaserProfile, load_laser_profile
from onestroke.errors import InputError

PROFILE = load_laser_profile()
DRAWINGS = {"rose": rose_drawing, "text": lambda: hershey_text_drawing("onestroke"),
            "wiggle": lambda: wiggle_drawing(300)}
CASES = [
    ("rose", dict(), dict()),
    ("rose", dict(arcs=True), dict(passes=3, return_home=True)),
    ("text", dict(), dict(air_assist=True, passes=2)),
    ("text", dict(arcs=True, origin="center"), dict(feed=4000.0, power=1.0)),
    ("wiggle", dict(arcs=True, tolerance=0.05), dict(dynamic=False, power=0.05)),
    ("wiggle", dict(optimize=False), dict()),
]


def _program(name, toolpath_kw, gcode_kw, profile=PROFILE):
    drawing = DRAWINGS[name]()
    tp = plan_toolpath(drawing, profile, ToolpathOptions(placement=PlacementOptions(size=120), **toolpath_kw))
    return tp, gcode_lines(tp, profile, GcodeOptions(**gcode_kw), comments=("test job",))


@pytest.mark.parametrize("name,toolpath_kw,gcode_kw", CASES)
def test_every_line_is_strict_grbl(name, toolpath_kw, gcode_kw):
    tp, lines = _program(name, toolpath_kw, gcode_kw)
    assert grbl_refusals(lines) == []
    text = gcode_text(lines)
    assert "\r" not in text and text.endswith("\n") and not text.endswith("\n\n")
    for line in text.split("\n")[:-1]:
        assert len(line) <= 80 and line == line.rstrip() and line
        assert len(strip_line(line)) <= 80
        # compact numbers: no trailing zeros, at most 3 decimals, no "-0"
        for number in __import__("re").findall(r"[A-Z]([-+]?\d*\.?\d+)", strip_line(line)):
            if "." in number:
                assert not number.endswith("0") and len(number.split(".")[1]) <= 3
            assert number not in ("-0",)
    if gcode_kw.get("arcs") or toolpath_kw.get("arcs"):
        assert any(strip_line(line).startswith(("G2", "G3")) for line in lines)


@pytest.mark.parametrize("name,toolpath_kw,gcode_kw", CASES)
def test_program_structure(name, toolpath_kw, gcode_kw):
    tp, lines = _program(name, toolpath_kw, gcode_kw)
    code = [strip_line(line) for line in lines if strip_line(line)]
    spindle_word = "M3S0" if gcode_kw.get("dynamic") is False else "M4S0"
    assert code[:3] == ["G21", "G90", spindle_word]
    air = gcode_kw.get("air_assist", PROFILE.air_assist)
    assert ("M8" in code) == bool(air) and (code[3] == "M8") == bool(air)
    tail = code[-3:] if gcode_kw.get("return_home") else code[-2:]
    assert tail[:2] == ["M5", "M9"]
    if gcode_kw.get("return_home"):
        assert tail[2] == "G0X0Y0"
    # spindle and coolant words appear only in the header and footer: no forced stops between strokes
    body = code[4 if air else 3:-len(tail)]
    assert not any(w in line for line in body for w in ("M3", "M4", "M5", "M7", "M8", "M9", "G4"))
    # a G0 to each stroke's start, and S and F on the first burn move after it
    power = fmt(gcode_kw.get("power", 0.6) * PROFILE.max_power)
    feed = fmt(gcode_kw.get("feed", 1500.0))
    after_g0 = [body[i + 1] for i, line in enumerate(body[:-1]) if line.startswith("G0")]
    assert after_g0 and all(f"S{power}F{feed}" in line for line in after_g0)
    # burn moves = planned moves x passes; every stroke has its G0 (or starts where the last ended)
    moves = parse_gcode(lines)
    passes = gcode_kw.get("passes", 1)
    assert int(moves.laser_on.sum()) == tp.segment_count * passes
    assert not moves.laser_on[moves.kind == 0].any()
    assert np.all(moves.power[moves.laser_on] == float(power))


@pytest.mark.parametrize("name,toolpath_kw,gcode_kw", CASES)
def test_moves_inside_bed_and_no_zero_length(name, toolpath_kw, gcode_kw):
    tp, lines = _program(name, toolpath_kw, gcode_kw)
    moves = parse_gcode(lines)
    pts = np.vstack([moves.start[1:], moves.end] + [sample_arc(moves, k) for k in np.flatnonzero(moves.kind >= 2)])
    assert pts.min() >= 0 and pts[:, 0].max() <= PROFILE.bed_width and pts[:, 1].max() <= PROFILE.bed_height
    lengths = np.hypot(*(moves.end - moves.start).T)
    assert np.all(lengths[moves.kind != 0] > 0)
    if toolpath_kw.get("origin") == "center":
        burn = np.vstack([moves.start[moves.laser_on], moves.end[moves.laser_on]])
        centre = (burn.min(axis=0) + burn.max(axis=0)) / 2
        assert np.allclose(centre, [PROFILE.bed_width / 2, PROFILE.bed_height / 2], atol=0.01)
    else:
        # the burned points start within the tolerance of the curve's own lower-left corner
        assert np.all(pts[1:].min(axis=0) <= tp.tolerance)


def sample_arc(moves, k, step=0.002):
    """Points along arc move k every `step` radians (independent of the library's code).

    The radius runs from the start's to the end's (they differ by the rounding of I, J):
    GRBL also lands exactly on the end point.
    """
    a, b, c = moves.start[k], moves.end[k], moves.centre[k]
    t0, t1 = np.arctan2(*(a - c)[::-1]), np.arctan2(*(b - c)[::-1])
    if moves.kind[k] == 3:
        t1 = t1 + 2 * np.pi if t1 <= t0 else t1
    else:
        t1 = t1 - 2 * np.pi if t1 >= t0 else t1
    t = np.linspace(t0, t1, max(3, int(abs(t1 - t0) / step)))
    r = np.linspace(np.hypot(*(a - c)), np.hypot(*(b - c)), len(t))
    return c + r[:, None] * np.c_[np.cos(t), np.sin(t)]


def test_arcs_never_bulge_out_of_the_bed():
    # a circle touching x = 0 and y = 0: arcs fitted there must not cross the bed edge
    from vectorize.drawing import Drawing
    from benchmarks.sets.laser_jobs import catmull_rom_stroke

    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    drawing = Drawing((catmull_rom_stroke(np.c_[np.cos(t), np.sin(t)] * 100 + 200, closed=True),), 400, 400, "px")
    tp = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=30), arcs=True,
                                                         tolerance=0.1))
    moves = parse_gcode(gcode_lines(tp, PROFILE, GcodeOptions()))
    arcs = np.flatnonzero(moves.kind >= 2)
    assert len(arcs) >= 1
    pts = np.vstack([sample_arc(moves, k) for k in arcs])
    assert pts.min() >= -1e-9


def test_drawing_is_not_mirrored():
    # an "L": long stroke down the left side then right along the bottom (screen, y down)
    from vectorize.drawing import Drawing
    from vectorize.stroke import Stroke

    drawing = Drawing((Stroke.from_polyline(np.array([[0, 0], [0, 100], [50, 100]])),), 100, 100, "px")
    tp = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=10), optimize=False))
    pts = tp.paths[0].points
    # machine y is up: the screen top (y=0) is the highest machine y, the foot is at y=0
    assert np.allclose(pts, [[0, 10], [0, 0], [5, 0]])


def test_framing_program_is_valid_and_traces_the_box():
    tp, _ = _program("rose", {}, {})
    for power in (0.0, 0.01):
        lines = framing_lines(tp.bounds, power_s=power * PROFILE.max_power)
        assert grbl_refusals(lines) == []
        moves = parse_gcode(lines)
        ends = moves.end[1:]
        xmin, ymin, xmax, ymax = tp.bounds
        assert np.allclose(np.unique(np.round(ends[:, 0], 3)), np.round([xmin, xmax], 3))
        assert np.allclose(np.unique(np.round(ends[:, 1], 3)), np.round([ymin, ymax], 3))
        assert moves.laser_on.any() == (power > 0)
        job = estimate_gcode_time(lines, PROFILE)
        perimeter = 2 * (xmax - xmin + ymax - ymin)
        assert job.burn_length == pytest.approx(perimeter if power > 0 else 0.0, abs=0.01)


def test_validator_accepts_a_consistent_arc_and_comments():
    lines = ["; header (ok)", "G21 (mm)", "G90", "M4S0", "G0X10Y0", "G3X0Y10I-10F500S300", "G2X10Y0J-10", "M5"]
    assert grbl_refusals(lines) == []


def test_gcode_options_refuse_bad_values():
    for kw in (dict(feed=0.0), dict(feed=-5.0), dict(power=0.0), dict(power=1.5), dict(passes=0)):
        with pytest.raises(InputError):
            GcodeOptions(**kw)


def test_bed_check_refuses_large_drawings():
    small = LaserProfile(name="tiny", bed_width=50, bed_height=50)
    with pytest.raises(InputError, match="does not fit the bed"):
        plan_toolpath(rose_drawing(), small, ToolpathOptions(placement=PlacementOptions(size=60)))
    plan_toolpath(rose_drawing(), small, ToolpathOptions(placement=PlacementOptions(size=50)))


def test_same_input_same_bytes():
    a = gcode_text(_program("text", dict(arcs=True), {})[1])
    b = gcode_text(_program("text", dict(arcs=True), {})[1])
    assert a == b
