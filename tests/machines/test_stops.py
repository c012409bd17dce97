"""Stopping safely, attaching without a reset, and progress off a terminal (emulator on a real pty).

Waits are event-driven: the tests block on the emulator's own condition (`wait_until`) or on
the child's output, never on a fixed sleep.
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time

import pytest
from click.testing import CliRunner

from tests.machines.emulator_link import stream_in_child
from fabrication.cli import main
from fabrication.cli.stream_cmd import run_stream
from machines.emulator import Faults
from machines.gcode_program import program_from_text
from machines.ports import open_port
from machines.streamer import GrblStreamer, StreamInterrupted
from onestroke.errors import MachineError
from tests.machines.test_stream import job_text, last_acked


# long moves: the planner holds seconds of motion, so only a feed hold stops the machine
LONG_MOVES = "\n".join(["G21", "G90", "M4S600", "G0X100Y100", "F3000"]
                       + [f"G1X{100 + 10 * (i % 2)}Y{100 + 0.05 * i:.2f}" for i in range(400)] + ["M5"]) + "\n"


@pytest.mark.parametrize("dropped", [0, 1], ids=["hold-heard", "hold-lost"])
def test_abort_resets_within_a_second_of_the_signal(emulator, dropped):
    emu = emulator(time_scale=2.0, faults=Faults(drop_hold=dropped))
    streamer = GrblStreamer(open_port(emu.device))
    signalled = []

    def stop_when_burning():
        emu.wait_until(lambda: len(emu.executed) >= 25, timeout=30)
        signalled.append(time.monotonic())
        streamer.abort()

    thread = threading.Thread(target=stop_when_burning)
    try:
        streamer.connect()
        thread.start()
        with pytest.raises(StreamInterrupted) as info:
            streamer.stream(program_from_text(LONG_MOVES))
    finally:
        thread.join()
        streamer.close()
    report = info.value.halt
    assert report.holds_sent == 1 + dropped and report.confirmed
    # the emulator's own clock: the reset arrived within 1 s of the stop signal
    assert emu.reset_times[-1] - signalled[0] < 1.0
    assert len(emu.hold_times) == 1  # exactly one feed hold reached the firmware
    message = str(info.value)
    assert "beam off" in message and ("sent twice" in message) == bool(dropped)
    assert 20 <= last_acked(message) <= len(emu.executed)
    assert not emu.beam_on


def test_ctrl_c_with_a_lost_feed_hold_resets_within_a_second(tmp_path, emulator):
    emu = emulator(time_scale=2.0, faults=Faults(drop_hold=1))
    path = tmp_path / "job.gcode"
    path.write_text(LONG_MOVES)
    process = stream_in_child(path, emu.device)
    assert emu.wait_until(lambda: len(emu.executed) >= 25, timeout=60)
    assert emu.beam_on  # burning when interrupted
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=30)
    errors = [line for line in stderr.splitlines() if line.startswith("error:")]
    assert process.returncode == 130 and len(errors) == 1, stderr
    assert "Ctrl-C" in errors[0] and "feed hold sent twice" in errors[0] and "beam off" in errors[0]
    assert float(re.search(r"machine reset ([\d.]+) s after the stop", errors[0]).group(1)) < 1.0
    # the emulator's own clock agrees: reset within 1 s of the signal, one hold heard
    assert emu.reset_times[-1] - sent < 1.0 and len(emu.hold_times) == 1
    assert not emu.beam_on and 20 <= last_acked(errors[0]) <= len(emu.executed)


def _start_foreign_job(emu, lines: int) -> int:
    """Another program's job: lines written straight to the pty, nobody reading the answers."""
    fd = os.open(emu.device, os.O_RDWR | os.O_NOCTTY)
    os.write(fd, ("".join(f"{line}\n" for line in job_text(lines).splitlines()[:12])).encode())
    emu.wait_until(lambda: emu.state == "Run", timeout=10)
    return fd


def test_no_reset_refuses_a_running_job_then_attaches_without_reset(tmp_path, emulator):
    emu = emulator(time_scale=5.0)
    fd = _start_foreign_job(emu, 20)
    path = tmp_path / "job.gcode"
    path.write_text(job_text(30))
    try:
        result = CliRunner().invoke(main, ["stream", str(path), "--port", emu.device, "--no-reset"])
        assert result.exit_code == 1 and "busy (Run)" in result.stderr
        assert emu.resets == 0 and emu.stats().state == "Run"  # the other job was not touched
        assert emu.wait_idle(30)
    finally:
        os.close(fd)
    before = len(emu.executed)
    result = CliRunner().invoke(main, ["stream", str(path), "--port", emu.device, "--no-reset"])
    assert result.exit_code == 0, result.output
    assert emu.resets == 0 and len(emu.executed) > before + 30


def test_plain_progress_lines_when_not_on_a_terminal(tmp_path, emulator, capsys):
    emu = emulator(time_scale=10.0)
    path = tmp_path / "job.gcode"
    path.write_text(job_text(1500))
    run_stream(path, port=emu.device, progress_every=0.3)
    err = capsys.readouterr().err
    progress = [line for line in err.splitlines() if "lines acknowledged" in line]
    assert len(progress) >= 2, err
    assert re.match(r"^\d+/\d+ lines acknowledged \(\d+ %\), elapsed [\d.:]+( s)?, remaining [\d.:]+( s)?$",
                    progress[0]), progress[0]


def test_dollar_lines_need_allow_settings(tmp_path, emulator):
    emu = emulator(time_scale=5.0)
    path = tmp_path / "job.gcode"
    path.write_text("$32=1\n" + job_text(20))
    result = CliRunner().invoke(main, ["stream", str(path), "--port", emu.device])
    assert result.exit_code == 2 and "--allow-settings" in result.stderr and emu.executed == []
    result = CliRunner().invoke(main, ["stream", str(path), "--port", emu.device, "--allow-settings"])
    assert result.exit_code == 0, result.output
    assert "$32=1" in emu.commands


def test_attach_without_reset_needs_an_answer(emulator):
    emu = emulator(time_scale=5.0, faults=Faults(silent=True))
    streamer = GrblStreamer(open_port(emu.device))
    try:
        with pytest.raises(MachineError, match="no status"):
            streamer.connect(reset=False)
    finally:
        streamer.close()
    assert emu.resets == 0
