"""Emulator motion: the planner core driven block by block, limits, probing, holds."""

import time

import pytest
from tests.machines.emulator_link import answered


def test_soft_limit_alarm_and_check_mode(link):
    grbl = link(settings={22: 1, 20: 1, 130: 100, 131: 100})
    assert "unlock" in grbl.send(b"\x18", until=lambda l: "unlock" in l)[-1]  # homing enabled: boots locked
    assert grbl.send(b"$H\n", until=answered) == ["ok"]
    assert grbl.send(b"G0X150\n", until=lambda l: "Reset" in l) == ["ALARM:2", "[MSG:Reset to continue]"]
    assert grbl.send(b"\x18", until=lambda l: "unlock" in l)[-1] == "[MSG:'$H'|'$X' to unlock]"
    assert grbl.send(b"$X\n", until=answered)[-1] == "ok"
    assert grbl.send(b"$C\n", until=answered) == ["[MSG:Enabled]", "ok"]
    assert grbl.send(b"G1X10F100\n", until=answered) == ["ok"]
    assert grbl.send(b"G5\n", until=answered) == ["error:20"]
    assert grbl.emu.stats().blocks_executed == 0  # check mode parses, never moves
    assert grbl.send(b"$C\n", until=lambda l: l.startswith("Grbl"))[-1].startswith("Grbl")


def test_planner_timing_single_move_and_limited_time(link):
    grbl = link(time_scale=10.0)
    start = time.monotonic()
    grbl.port.write(b"G1X100F3000\nG4P0\n")
    replies = grbl.lines(3.0, until=lambda l: grbl.emu.stats().blocks_executed == 1)
    wall = time.monotonic() - start
    stats = grbl.emu.stats()
    # 100 mm at 50 mm/s, a = 500 mm/s^2: 2.1 s of machine time, 0.21 s at 10x.
    assert stats.planner_limited_time == pytest.approx(2.1, rel=1e-6)
    assert stats.motion_time == pytest.approx(2.1, rel=0.05)
    assert 0.2 < wall < 0.6
    assert replies


def test_probe_without_contact_ends_in_alarm_5(link):
    grbl = link()
    replies = grbl.send(b"G21G90\nM4S300\nG38.2X5F600\n", until=lambda l: l.startswith("ALARM"))
    assert replies[-1] == "ALARM:5" and grbl.emu.alarms == [5] and not grbl.emu.beam_on
    assert grbl.send(b"G0X1\n", until=answered)[-1] == "error:9"  # locked until $X
    replies = grbl.send(b"G38.3X8F600\n", until=answered)  # no alarm for G38.3 once unlocked
    assert replies[-1] == "error:9"


def test_planner_limited_time_is_the_estimate_s_planner_time(link):
    # the emulator's blocks, timed by the batch driver, equal the estimate's planner figure
    from machines.gcode_program import analyze_program, program_from_text
    from machines.ports import open_port
    from machines.streamer import GrblStreamer

    grbl = link(time_scale=50.0)
    text = "G21G90\nM4S500\nG0X10Y10\nF2000\n" + "".join(
        f"G1X{10 + 0.3 * i:.3f}Y{10 + (i % 7) * 0.2:.3f}\n" for i in range(120)) + "G2X55.7Y10I5J0\nM5\n"
    grbl.port.close()
    with GrblStreamer(open_port(grbl.emu.device)) as streamer:
        streamer.connect()
        streamer.stream(program_from_text(text))
    stats = analyze_program(program_from_text(text), settings=grbl.emu.settings)
    assert grbl.emu.stats().planner_limited_time == pytest.approx(stats.total_seconds, rel=1e-9)


def status_x(grbl):
    """X of the machine position in a status report (`?`)."""
    return float(grbl.send(b"?", until=lambda l: l.startswith("<"))[-1].split("MPos:")[1].split(",")[0])


def test_feed_hold_stops_inside_the_block_and_resumes(link):
    grbl = link(time_scale=5.0)
    grbl.port.write(b"G21G90\nM4S500\nG1X200F3000\n")
    assert grbl.emu.wait_until(lambda: grbl.emu.state == "Run", timeout=10)
    # moving (the clock starts the block once it is sure no line from us comes first)
    deadline = time.monotonic() + 10
    while status_x(grbl) < 1.0 and time.monotonic() < deadline:
        time.sleep(0.01)
    grbl.port.write(b"!")
    assert grbl.emu.wait_until(lambda: grbl.emu.state == "Hold:0", timeout=10)
    held = grbl.emu.stats()
    x = status_x(grbl)
    assert 0 < x < 200 and held.blocks_executed == 0
    grbl.port.write(b"~")
    assert grbl.emu.wait_idle(30) and grbl.emu.stats().blocks_executed == 1
