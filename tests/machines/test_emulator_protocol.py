"""Emulator protocol: welcome, `$` commands, errors, status reports and real-time bytes."""

import time

import pytest
from tests.machines.emulator_link import answered


def test_welcome_info_settings_and_modal_state(link):
    grbl = link()
    assert grbl.send(b"\x18", until=lambda l: l.startswith("Grbl")) == ["Grbl 1.1h ['$' for help]"]
    assert grbl.send(b"$I\n", until=answered) == ["[VER:1.1h.20190825:]", "[OPT:V,15,128]", "ok"]
    settings = grbl.send(b"$$\n", until=answered)
    assert "$30=1000" in settings and "$32=1" in settings and "$110=6000.000" in settings
    assert grbl.send(b"$G\n", until=answered)[0].startswith("[GC:G0 G54 G17 G21 G90 G94 M5")
    assert grbl.send(b"$Q\n", until=answered) == ["error:2"]  # system.c: no setting number to read


def test_errors_unsupported_too_long_feed_undefined(link):
    grbl = link()
    assert grbl.send(b"G5 X1\n", until=answered) == ["error:20"]
    assert grbl.send(b"G1X" + b"1" * 80 + b"\n", until=answered) == ["error:11"]
    assert grbl.send(b"G1 X1 (a comment does not count) ; nor this\n", until=answered) == ["error:22"]
    # CR LF is two line ends for GRBL: two answers.
    assert grbl.send(b"G21\r\n", until=None, wait=0.3) == ["ok", "ok"]
    assert grbl.emu.executed == ["G21"]


def test_realtime_status_hold_resume_and_reset_alarm(link):
    grbl = link(time_scale=5.0)
    assert grbl.send(b"G1X100F3000\n", until=answered) == ["ok"]
    time.sleep(0.05)
    status = grbl.send(b"?", until=lambda l: l.startswith("<"))[-1]
    assert status.startswith("<Run|MPos:") and "FS:" in status
    grbl.send(b"!", wait=0.02)
    hold = grbl.send(b"?", until=lambda l: l.startswith("<"))[-1]
    assert hold.startswith("<Hold:")
    time.sleep(0.1)
    assert grbl.send(b"?", until=lambda l: l.startswith("<"))[-1].startswith("<Hold:0")
    stopped_at = grbl.emu.position[0]
    assert 0 < stopped_at < 100
    grbl.send(b"~", wait=0.05)
    assert grbl.send(b"?", until=lambda l: l.startswith("<"))[-1].startswith("<Run")
    replies = grbl.send(b"\x18", until=lambda l: "unlock" in l)  # reset while moving
    assert replies[:2] == ["ALARM:3", "Grbl 1.1h ['$' for help]"] and "unlock" in replies[-1]
    assert grbl.send(b"G0X0\n", until=answered) == ["error:9"]
    assert grbl.send(b"$X\n", until=answered) == ["[MSG:Caution: Unlocked]", "ok"]
    assert not grbl.emu.beam_on
