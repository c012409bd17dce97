"""Streaming to the emulator on a real pty: completeness, flow control, speed, pause/resume,
and every fault path through the `onestroke stream` command (beam off, one line, exit code)."""

import math
import re
import signal
import subprocess
import sys
import threading
import time

import pytest
from click.testing import CliRunner

from tests.machines.emulator_link import hear_ctrl_c, stream_in_child
from fabrication.cli import main
from machines.emulator import Faults
from machines.gcode_program import program_from_text
from machines.job_time import estimate_program_time
from machines.laser_profile import load_laser_profile
from machines.ports import open_port
from machines.streamer import DRAIN_LINE, GrblStreamer, StreamOptions
from onestroke.errors import MachineError


def job_text(n, *, step=0.5, feed=3000, seed=0):
    """A curvy single-stroke job of n G1 lines (no blank lines: file line k = program line k)."""
    lines = ["G21", "G90", "M4 S600", "G0 X100 Y100", f"F{feed}"]
    x = y = 100.0
    for i in range(n):
        t = 0.004 * i + seed
        x += step * math.cos(3 * math.sin(t * 2.0) + t)
        y += step * math.sin(3 * math.sin(t * 2.0) + t)
        lines.append(f"G1X{x:.3f}Y{y:.3f}")
    lines += ["M5", "G0X0Y0"]
    return "\n".join(lines) + "\n"


def cleaned(text):
    return [line for _, line in program_from_text(text).lines]


def stream(emu, text, **options):
    port = open_port(emu.device)
    streamer = GrblStreamer(port, options=StreamOptions(**options))
    try:
        streamer.connect()
        emu.mark_job_start()  # stats().job_time: the job on the emulator's machine clock
        return streamer.stream(program_from_text(text))
    finally:
        streamer.close()


def test_job_runs_every_line_once_in_order_without_overflow_near_planner_time(emulator):
    emu = emulator(time_scale=4.0)
    text = job_text(1500, step=0.4)
    stream(emu, text)
    stats = emu.stats()
    assert emu.executed == cleaned(text) + [DRAIN_LINE]
    assert stats.rx_overflow_bytes == 0 and stats.max_rx_used <= 128
    ratio = stats.job_time / stats.planner_limited_time
    print(f"\ncharacter counting: {stats.job_time:.2f} s machine, planner-limited "
          f"{stats.planner_limited_time:.2f} s, ratio {ratio:.3f}")
    # Machine time (the emulator's clock does not depend on the host's load): the stream
    # keeps the planner fed, only the first line's way in and the last `ok` add to it.
    assert 1.0 <= ratio <= 1.02
    assert not emu.beam_on and stats.state == "Idle"


def test_send_response_is_slower_on_dense_work(emulator):
    text = job_text(600, step=0.1, feed=5000)  # dense work: 0.1 mm lines
    times = {}
    for mode in (False, True):
        emu = emulator(time_scale=4.0)
        stream(emu, text, send_response=mode)
        assert emu.executed == cleaned(text) + [DRAIN_LINE]
        times[mode] = emu.stats().job_time / emu.stats().planner_limited_time
    print(f"\nratio to planner-limited time: character counting {times[False]:.3f}, "
          f"send-response {times[True]:.3f}")
    # machine time: a round trip per line (USB latency both ways, the answer's wire time)
    # starves the planner on dense work, whatever the host computer's load
    assert times[False] < 1.02 and times[True] > times[False] + 0.05


def test_machine_time_is_the_estimate_s_whatever_the_host_s_load(emulator):
    # dense 0.1 mm lines at F5000: the link, the parser and a starved planner all count
    text = job_text(400, step=0.1, feed=5000)
    estimate = estimate_program_time(program_from_text(text + DRAIN_LINE + "\n"), load_laser_profile())
    times = []
    for busy in (False, True):
        stop = threading.Event()
        if busy:  # a host that is slow to answer: another thread of this process spins
            threading.Thread(target=lambda: [None for _ in iter(stop.is_set, True)], daemon=True).start()
        emu = emulator(time_scale=4.0)
        try:
            stream(emu, text)
        finally:
            stop.set()
        assert emu.executed == cleaned(text) + [DRAIN_LINE]
        times.append(emu.stats().job_time)
    print(f"\nmachine time {times[0]:.3f} s, with a busy host {times[1]:.3f} s; estimate "
          f"{estimate.total_seconds:.3f} s ({estimate.bound})")
    assert times[1] == pytest.approx(times[0], rel=0.01)
    assert estimate.total_seconds == pytest.approx(times[0], rel=0.01)


def test_pause_and_resume_lose_and_repeat_nothing(emulator):
    emu = emulator(time_scale=10.0)
    text = job_text(800)
    port = open_port(emu.device)
    streamer = GrblStreamer(port)
    streamer.connect()
    done = {}
    thread = threading.Thread(target=lambda: done.setdefault("result", streamer.stream(program_from_text(text))))
    thread.start()
    assert emu.wait_until(lambda: len(emu.executed) >= 300, timeout=20)
    streamer.pause()
    assert streamer.wait_status(lambda s: s.full_state == "Hold:0", 3.0) is not None
    moved = emu.stats().blocks_executed
    # GRBL keeps parsing into the planner during a hold until it is full
    assert emu.wait_until(lambda: len(emu.planner) == emu.options.planner_blocks, timeout=5)
    held = len(emu.executed)
    time.sleep(0.3)
    assert len(emu.executed) == held and emu.stats().blocks_executed == moved  # nothing moves in Hold:0
    assert not emu.beam_on or not emu._motion_busy
    streamer.resume()
    streamer.feed_override(10)
    streamer.power_override(-10)
    report = streamer.wait_status(lambda s: s.overrides == (110, 100, 90), 3.0)
    assert report is not None and (emu.feed_ov, emu.spindle_ov) == (110, 90)
    thread.join(30)
    streamer.close()
    assert "result" in done
    assert emu.executed == cleaned(text) + [DRAIN_LINE]
    assert emu.position[:2] == pytest.approx((0.0, 0.0))  # the last move (G0X0Y0) completed


def test_eeprom_writers_go_one_at_a_time_and_lose_nothing(emulator):
    emu = emulator(time_scale=5.0)
    lines = job_text(300).splitlines()
    text = "\n".join(["$110=6000", "$111=6000"] + lines[:100] + ["G10L2P1X0Y0", "G28.1"] + lines[100:200]
                     + ["G10L20P1X0Y0"] + lines[200:]) + "\n"
    stream(emu, text)
    assert emu.stats().eeprom_lost_bytes == 0
    assert emu.commands[-2:] == ["$110=6000", "$111=6000"]
    assert emu.executed == [line for line in cleaned(text) if not line.startswith("$")] + [DRAIN_LINE]


def test_eeprom_writers_streamed_like_other_lines_lose_bytes(emulator, monkeypatch):
    # The control for the test above: without send-response the firmware drops input.
    monkeypatch.setattr("machines.streamer.is_eeprom_writer", lambda line: False)
    emu = emulator(time_scale=2.0)
    lines = job_text(300).splitlines()
    text = "\n".join(["$110=6000"] + lines) + "\n"
    port = open_port(emu.device)
    streamer = GrblStreamer(port, options=StreamOptions(watchdog=0.5))
    # What the firmware makes of the mangled lines is arbitrary (some runs leave it moving
    # without end): the stream must end in a MachineError, by a fault or, at worst, by abort.
    safety = threading.Timer(30.0, streamer.abort)
    safety.start()
    try:
        with pytest.raises(MachineError):
            streamer.connect()
            streamer.stream(program_from_text(text))
    finally:
        safety.cancel()
        streamer.close()
    assert emu.stats().eeprom_lost_bytes > 0


# ---------------------------------------------------------------- faults, through the CLI

def run_cli(tmp_path, emu, text, *extra):
    path = tmp_path / "job.gcode"
    path.write_text(text)
    result = CliRunner().invoke(main, ["stream", str(path), "--port", emu.device, *extra])
    errors = [line for line in result.stderr.splitlines() if line.startswith("error:")]
    return result, errors


def assert_beam_off_after(emu):
    assert not emu.beam_on
    assert emu.resets >= 2 or emu.spindle_history[-1][0] == "M5" or emu.disconnected


def last_acked(message):
    match = re.search(r"last acknowledged line (\d+)", message)
    assert match, message
    return int(match.group(1))


def test_error_mid_job(tmp_path, emulator):
    emu = emulator(faults=Faults(error_at=400))
    result, errors = run_cli(tmp_path, emu, job_text(1000))
    assert result.exit_code == 1 and len(errors) == 1
    assert "line 400" in errors[0] and "error:20" in errors[0]
    assert last_acked(errors[0]) == 399
    assert_beam_off_after(emu)
    assert 3 not in emu.alarms  # reset after the hold: no ALARM:3


def test_alarm_mid_job(tmp_path, emulator):
    emu = emulator(faults=Faults(alarm_at=500))
    result, errors = run_cli(tmp_path, emu, job_text(1000))
    assert result.exit_code == 1 and len(errors) == 1
    assert "ALARM:1" in errors[0] and "Hard limit" in errors[0] and "$H" in errors[0]
    assert last_acked(errors[0]) == 499
    assert_beam_off_after(emu)


def test_port_closed_mid_job(tmp_path, emulator):
    emu = emulator(faults=Faults(disconnect_at=300))
    result, errors = run_cli(tmp_path, emu, job_text(1000))
    assert result.exit_code == 1 and len(errors) == 1
    assert "lost the connection" in errors[0]
    assert 290 <= last_acked(errors[0]) <= 300
    assert_beam_off_after(emu)


def test_garbage_bytes_on_the_line(tmp_path, emulator):
    emu = emulator(faults=Faults(garbage_at=250))
    result, errors = run_cli(tmp_path, emu, job_text(1000))
    assert result.exit_code == 1 and len(errors) == 1
    assert "unreadable bytes" in errors[0]
    assert 250 <= last_acked(errors[0]) <= 260
    assert_beam_off_after(emu)


def test_a_line_longer_than_the_receive_buffer_is_refused_before_sending(tmp_path, emulator):
    # Character counting waits for room in GRBL's buffer; a line bigger than the whole
    # buffer never gets it (this hung the CLI and the studio's "Send" forever).
    emu = emulator(rx_buffer=12)
    result, errors = run_cli(tmp_path, emu, "G21\nG90\nG1X10.000Y10.000F1000\nM5\n")
    assert result.exit_code == 1 and len(errors) == 1, result.output
    assert "line 3 is 22 bytes" in errors[0] and "12-byte receive buffer" in errors[0] and "nothing was sent" in errors[0]
    assert emu.executed == [] and not emu.beam_on


def test_no_answer_at_connect(tmp_path, emulator):
    emu = emulator(faults=Faults(silent=True))
    result, errors = run_cli(tmp_path, emu, job_text(10))
    assert result.exit_code == 1 and len(errors) == 1
    assert "no answer" in errors[0] and "no line was acknowledged" in errors[0]
    assert emu.executed == [] and not emu.beam_on


@pytest.mark.parametrize("report_mask", [1, 3], ids=["no-Bf", "with-Bf"])
def test_lost_ok(tmp_path, emulator, report_mask):
    emu = emulator(faults=Faults(drop_ok_at=200), settings={10: report_mask})
    result, errors = run_cli(tmp_path, emu, job_text(400))
    assert result.exit_code == 1 and len(errors) == 1
    assert "'ok' was lost" in errors[0]
    assert last_acked(errors[0]) >= 200  # later answers are attributed one line early
    assert_beam_off_after(emu)


@pytest.mark.parametrize("report_mask", [1, 3], ids=["no-Bf", "with-Bf"])
def test_idle_stall_with_queued_blocks_is_recovered(tmp_path, emulator, report_mask):
    emu = emulator(faults=Faults(stall_at=300), settings={10: report_mask})
    text = job_text(600)
    result, errors = run_cli(tmp_path, emu, text)
    assert result.exit_code == 0, result.output
    assert "stalled Idle" in result.stderr and errors == []
    assert emu.executed == cleaned(text) + [DRAIN_LINE]


def test_ctrl_c_halts_safely(tmp_path, emulator):
    emu = emulator(time_scale=5.0)
    path = tmp_path / "job.gcode"
    path.write_text(job_text(3000))
    process = stream_in_child(path, emu.device)
    assert emu.wait_until(lambda: len(emu.executed) >= 400, timeout=30)
    assert emu.beam_on  # burning when interrupted
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=30)
    errors = [line for line in stderr.splitlines() if line.startswith("error:")]
    assert process.returncode == 130 and len(errors) == 1
    # The oks of the last few executed lines may still be on the wire when Ctrl-C lands.
    assert "Ctrl-C" in errors[0] and 350 <= last_acked(errors[0]) <= len(emu.executed)
    assert_beam_off_after(emu)
    assert 3 not in emu.alarms and emu.stats().state == "Idle"


def test_alarm_at_boot_is_reported_with_the_unlock_hint(tmp_path, emulator):
    emu = emulator(boot_alarm=True)
    result, errors = run_cli(tmp_path, emu, job_text(10))
    assert result.exit_code == 1 and len(errors) == 1 and "$X" in errors[0] and "$H" in errors[0]
    assert emu.executed == []


def test_cli_check_mode_and_preflight_table(tmp_path, emulator):
    emu = emulator()
    result, errors = run_cli(tmp_path, emu, job_text(50), "--check")
    assert result.exit_code == 0 and "check passed" in result.stdout
    assert emu.stats().blocks_executed == 0
    emu = emulator(settings={30: 255})
    result, errors = run_cli(tmp_path, emu, job_text(50))
    assert result.exit_code == 2 and "$30=255" in errors[0] and emu.executed == []
    emu = emulator()
    result, errors = run_cli(tmp_path, emu, "G21\nG5 X1\n")
    assert result.exit_code == 2 and "line 2" in errors[0] and "error:20" in errors[0]
    result = CliRunner().invoke(main, ["stream", str(tmp_path / "nope.gcode"), "--port", "sim://"])
    assert result.exit_code == 2
    result = CliRunner().invoke(main, ["stream", str(tmp_path / "job.gcode"), "--port", "/dev/does-not-exist"])
    assert result.exit_code == 1 and "does not exist" in result.stderr
    result = CliRunner().invoke(main, ["stream", str(tmp_path / "job.gcode"), "--port", "sim://", "--baud", "7"])
    assert result.exit_code == 2 and "--baud 7" in result.stderr


def test_cli_sim_dry_run_and_frame(tmp_path):
    path = tmp_path / "job.gcode"
    path.write_text(job_text(200))
    result = CliRunner().invoke(main, ["stream", str(path), "--port", "sim://?speed=50"])
    assert result.exit_code == 0 and "streamed 207 lines" in result.stdout
    result = CliRunner().invoke(main, ["stream", str(path), "--port", "sim://?speed=50", "--frame"])
    assert result.exit_code == 0 and "framed" in result.stdout and "beam off" in result.stdout
    result = CliRunner().invoke(main, ["ports", "--no-probe"])
    assert result.exit_code == 0 and "serial port" in result.stdout


def test_emulator_command_serves_a_pty_and_logs_executed_lines(tmp_path):
    log = tmp_path / "executed.txt"
    process = subprocess.Popen([sys.executable, "-c", "from fabrication.cli import main; main()", "emulator",
                                "--speed", "50", "--log", str(log)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, preexec_fn=hear_ctrl_c)
    try:
        device = process.stdout.readline().strip()
        assert device.startswith("/dev/")
        path = tmp_path / "job.gcode"
        text = job_text(100)
        path.write_text(text)
        result = CliRunner().invoke(main, ["stream", str(path), "--port", device])
        assert result.exit_code == 0, result.output
    finally:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=10)
    assert process.returncode == 0 and "planner-limited" in out
    assert log.read_text().splitlines() == cleaned(text) + [DRAIN_LINE]


def test_resume_from_the_reported_line_finishes_the_job(tmp_path, emulator):
    text = job_text(600)
    emu = emulator(faults=Faults(error_at=300))
    result, errors = run_cli(tmp_path, emu, text)
    assert result.exit_code == 1 and "--from-line 300" in errors[0]
    fresh = emulator()
    result, errors = run_cli(tmp_path, fresh, text, "--from-line", "300")
    assert result.exit_code == 0, result.output
    assert "resuming" in result.stderr
    full = cleaned(text)
    preamble = fresh.executed[:len(fresh.executed) - len(full[299:]) - 1]
    assert preamble[0] == "M5" and preamble[-2:] == ["M4S600", "G1"]
    assert any(line.startswith("G53G0X") for line in preamble)
    assert fresh.executed[len(preamble):] == full[299:] + [DRAIN_LINE]
    # Where line 300 starts, the beam was off until the laser mode was restored.
    assert fresh.spindle_history[0][0] == "M5" or fresh.spindle_history[0][1] == 0
    result, errors = run_cli(tmp_path, emulator(), text, "--from-line", "99999")
    assert result.exit_code == 2 and "--from-line 99999" in errors[0]
