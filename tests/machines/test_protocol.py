"""GRBL protocol parsing, G-code semantics and the planner time model (pure functions)."""

import math

import pytest

from machines.gcode_interpreter import GcodeError, GcodeInterpreter, MachineConfig
from machines.gcode_program import analyze_program, program_from_text
from machines.grbl_codes import ALARM_CODES, ERROR_CODES, describe_alarm, describe_error
from machines.grbl_protocol import (Alarm, ErrorReply, Message, Ok, Setting, StatusReport, Unknown, Welcome,
                                    clean_line, is_alarm_lock_message, is_eeprom_writer, parse_options,
                                    parse_reply)
from machines.job_check import check_job
import numpy as np

from machines.planner_model import BlockBuilder, Kinematics, exit_speed, plan_times, trapezoid
from onestroke.errors import InputError


@pytest.mark.parametrize("raw, expected", [
    (b"ok", Ok()),
    (b"ok\r", Ok()),
    (b"error:20", ErrorReply(20)),
    (b"ALARM:2", Alarm(2)),
    (b"Grbl 1.1h ['$' for help]", Welcome("1.1h")),
    (b"[MSG:'$H'|'$X' to unlock]", Message("MSG", "'$H'|'$X' to unlock")),
    (b"[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", Message("GC", "G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0")),
    (b"[VER:1.1h.20190825:]", Message("VER", "1.1h.20190825:")),
    (b"[OPT:V,15,128]", Message("OPT", "V,15,128")),
    (b"$110=6000.000", Setting(110, 6000.0)),
    (b"$32=1", Setting(32, 1.0)),
    (b"\xfe\xffok", Unknown(b"\xfe\xffok")),
    (b"okay then", Unknown(b"okay then")),
])
def test_parse_reply_table(raw, expected):
    assert parse_reply(raw) == expected


def test_status_report_fields_by_key_any_may_be_missing():
    full = parse_reply(b"<Hold:0|MPos:1.000,2.500,0.000|Bf:12,100|Ln:7|FS:3000,600|Ov:110,100,90|A:CF|WCO:1,2,3>")
    assert isinstance(full, StatusReport)
    assert (full.state, full.substate, full.full_state) == ("Hold", 0, "Hold:0")
    assert full.mpos == (1.0, 2.5, 0.0) and full.wco == (1.0, 2.0, 3.0)
    assert (full.planner_free, full.rx_free, full.line_number) == (12, 100, 7)
    assert (full.feed, full.spindle, full.overrides, full.accessories) == (3000.0, 600.0, (110, 100, 90), "CF")
    bare = parse_reply(b"<Idle|WPos:0.000,0.000,0.000>")
    assert bare.state == "Idle" and bare.wpos == (0.0, 0.0, 0.0)
    assert bare.mpos is None and bare.planner_free is None and bare.feed is None and bare.overrides is None
    reordered = parse_reply(b"<Run|FS:100,5|MPos:1,1,1>")
    assert reordered.feed == 100.0 and reordered.mpos == (1.0, 1.0, 1.0)


def test_codes_tables_and_descriptions():
    assert len(ERROR_CODES) >= 30 and set(range(1, 11)) <= set(ALARM_CODES)
    assert "Unsupported" in describe_error(20) and "error:20" in describe_error(20)
    assert "$X" in describe_alarm(2) and "$H" in describe_alarm(1)
    assert "error:99" in describe_error(99)


def test_clean_line_strips_comments_spaces_and_percent():
    assert clean_line("g1 x10 (move) y2 ; go") == "G1X10Y2"
    assert clean_line("  ; only a comment") == ""
    assert clean_line("/g1x1") == "G1X1" and clean_line("G1X1(unclosed") == "G1X1"
    assert [text for _, text in program_from_text("%\nG1X1F100\n%").lines] == ["G1X1F100"]
    assert is_eeprom_writer("$110=500") and is_eeprom_writer("G10L2P1X0") and is_eeprom_writer("G28.1")
    assert not is_eeprom_writer("G1X10") and not is_eeprom_writer("$$")
    assert parse_options("V,15,128") == (15, 128) and parse_options("VL,35,254") == (35, 254)
    assert is_alarm_lock_message(Message("MSG", "'$H'|'$X' to unlock"))


@pytest.mark.parametrize("line, code", [
    ("G5X1", 20), ("M6", 20), ("G1X1", 22), ("G0G1X1", 24), ("G17G18", 21), ("X1X2", 25), ("G0X1Q2", 20),
    ("1X2", 1), ("G0X", 2), ("F-1", 4), ("G2X10Y0F100", 35), ("G2X10Y0R1F100", 34), ("G2X10Y0", 22), ("G4", 28), ("G80X1", 31),
])
def test_interpreter_refuses_like_grbl(line, code):
    with pytest.raises(GcodeError) as info:
        GcodeInterpreter().execute(line)
    assert info.value.code == code


def test_interpreter_moves_units_arcs_and_syncs():
    interp = GcodeInterpreter(MachineConfig(arc_tolerance=0.002))
    assert interp.execute("G20G90") == []
    move = interp.execute("G1X1F10")[-1]
    assert move[0] == "move" and move[1] == pytest.approx((25.4, 0.0, 0.0)) and move[2] == pytest.approx(254.0)
    interp.execute("G21G0X0Y0")
    spindle = interp.execute("M4S500")
    assert spindle == [("sync",), ("spindle", "M4", 0.0)] or ("spindle", "M4", 500.0) in spindle
    assert interp.execute("G1X1S600F100")[0][0] == "move"  # laser mode: S on a motion line does not stop
    arc = interp.execute("G2X11Y0I5J0")
    points = [a[1] for a in arc]
    assert len(points) > 10 and points[-1] == pytest.approx((11.0, 0.0, 0.0))
    for x, y, _ in points:  # every chord end lies on the circle around (6, 0)
        assert math.hypot(x - 6.0, y) == pytest.approx(5.0, abs=1e-6)
    assert ("sync",) in interp.execute("G4P0.5")
    assert interp.execute("G91G1X1")[-1][1] == pytest.approx((12.0, 0.0, 0.0))


def test_trapezoid_and_single_move_time():
    # 100 mm at 50 mm/s with a = 500 mm/s^2 from and to rest: 100/50 + 50/500 s.
    profile = trapezoid(0.0, 0.0, 50.0, 500.0, 100.0)
    assert profile.duration == pytest.approx(2.1)
    assert profile.distance_at(profile.duration) == pytest.approx(100.0)
    assert profile.speed_at(1.0) == pytest.approx(50.0)
    short = trapezoid(0.0, 0.0, 50.0, 500.0, 1.0)  # triangle: never reaches cruise
    assert short.peak == pytest.approx(math.sqrt(500.0)) and short.duration == pytest.approx(2 * math.sqrt(500) / 500)


def test_junction_deviation_speed_matches_formula():
    kin = Kinematics(acceleration=(500.0, 500.0, 10.0), junction_deviation=0.01)
    builder = BlockBuilder(kin)
    builder.make((0, 0, 0), (10, 0, 0), feed_mm_min=6000, rapid=False, from_rest=True)
    corner = builder.make((10, 0, 0), (10, 10, 0), feed_mm_min=6000, rapid=False, from_rest=False)
    s = math.sin(math.pi / 4)  # a 90 degree corner: theta/2 = 45 degrees
    a = 500.0 * math.sqrt(2)  # along the junction vector (-1, 1)/sqrt(2) each axis gives 500 mm/s^2
    assert corner.junction_sqr == pytest.approx(a * 0.01 * s / (1 - s))
    straight = builder.make((10, 10, 0), (10, 20, 0), feed_mm_min=6000, rapid=False, from_rest=False)
    reverse = builder.make((10, 20, 0), (10, 15, 0), feed_mm_min=6000, rapid=False, from_rest=False)
    assert straight.junction_sqr > 1e30 and reverse.junction_sqr == 0.0


def test_lookahead_caps_speed_on_short_segments():
    # 0.1 mm segments in a straight line: with 15 blocks of look-ahead the speed stays near
    # sqrt(2 a 14 L) and well under the programmed 100 mm/s.
    kin = Kinematics()
    builder = BlockBuilder(kin)
    blocks = [builder.make((i * 0.1, 0, 0), ((i + 1) * 0.1, 0, 0), feed_mm_min=6000, rapid=False,
                           from_rest=i == 0) for i in range(400)]
    start = np.c_[np.arange(400) * 0.1, np.zeros(400)]
    args = (start, start + [0.1, 0.0], np.full(400, 6000.0), np.zeros(400, bool), np.zeros(400, bool))
    durations = plan_times(*args, kin)
    cruise = 0.1 / durations[200]
    assert cruise == pytest.approx(math.sqrt(2 * 500 * 14 * 0.1), rel=0.05)
    assert exit_speed(blocks[:1]) == 0.0
    # the incremental driver's exit speed in mid-job equals the batch driver's cruise
    assert exit_speed(blocks[200:215]) == pytest.approx(cruise, rel=0.05)
    deeper = plan_times(*args, Kinematics(planner_blocks=30)).sum()
    assert deeper < durations.sum()


def test_program_analysis_and_job_check():
    program = program_from_text("G21 G90\nM4 S800\nG0 X10 Y10\nG1 X50 Y10 F1200\nG1 X50 Y30\nM5\n\n(c)\n")
    assert [n for n, _ in program.lines] == [1, 2, 3, 4, 5, 6]
    stats = analyze_program(program, settings={110: 6000, 111: 6000, 120: 500, 121: 500})
    assert stats.uses_laser and stats.max_s == 800
    assert stats.burn_extent == ((10.0, 10.0), (50.0, 30.0))
    assert len(stats.line_seconds) == len(program) and stats.total_seconds > 40 / 20
    ok = {30: 1000, 32: 1, 130: 400, 131: 400, 22: 0}
    assert check_job(stats, ok) == []
    fatal = [p.message for p in check_job(stats, {**ok, 30: 255}) if p.fatal]
    assert fatal and "S800" in fatal[0] and "$30=255" in fatal[0]
    assert any("$32=0" in p.message and p.fatal for p in check_job(stats, {**ok, 32: 0}))
    assert any("bed" in p.message and p.fatal for p in check_job(stats, {**ok, 130: 30, 131: 10}))
    with pytest.raises(InputError, match="line 1 has 90 characters"):
        program_from_text("G1X" + "1" * 87)


def test_resume_program_restores_state_and_refuses_offset_changes():
    from machines.resume import resume_program

    program = program_from_text("G21\nG91\nM8\nM4 S700\nG1 X5 Y5 F1200\nG1 X5\n(c)\nG1 Y-2\n")
    resumed = resume_program(program, 8)
    # Beam off, go where line 8 starts (machine coordinates), then restore units, relative
    # mode, feed, air assist, laser mode and power, and the motion mode.
    assert [text for _, text in resumed.lines] == [
        "M5", "G21", "G90", "G17", "G53G0X10.000Y5.000", "G21", "G91", "G94", "F1200", "M8", "M4S700", "G1",
        "G1Y-2"]
    assert [n for n, _ in resumed.lines if n] == [8]
    with pytest.raises(InputError, match="--from-line 7"):
        resume_program(program, 7)  # a comment line
    with pytest.raises(InputError, match="work offsets"):
        resume_program(program_from_text("G92X0Y0\nG1X1F100\n"), 2)
