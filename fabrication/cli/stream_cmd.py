"""`onestroke stream FILE.gcode --port PORT`: send a G-code job to a GRBL laser, safely.

Also `run_stream`, the same thing as a function, for `onestroke laser ... --port`.
"""

from __future__ import annotations

import contextlib
import os
import select
import sys
import threading
import time
from pathlib import Path

import click
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from fabrication.cli.common import console, done, warn
from fabrication.cli.common import progress_every as plain_progress_every
from fabrication.cli.options import Integer, Number, input_argument, machine_options, output_option
from machines.framing import DEFAULT_FRAME_FEED, framing_lines
from machines.gcode_program import Program, analyze_program, load_program, program_from_text
from machines.job_time import estimate_program_time, format_duration
from machines.job_check import check_job
from machines.ports import open_port
from machines.emulator import TIME_SCALE
from machines.resume import resume_program
from machines.stream_types import check_baud
from machines.streamer import GrblStreamer, MachineInfo, StreamError, StreamProgress
from onestroke.errors import InputError, MachineError
from onestroke.ranges import Range



def _format_seconds(seconds: float) -> str:
    # An ETA can dip below zero when the machine runs ahead of the model.
    return format_duration(max(0.0, float(seconds)))


def _machine_profile(info: MachineInfo, laser_profile):
    """The connected machine as a profile: its `$$` settings over the given (or default) profile."""
    from machines.grbl_settings import profile_from_settings

    return profile_from_settings(info.settings, base=laser_profile, rx_buffer=info.rx_buffer,
                                 planner_blocks=info.planner_blocks)


def _frame_program(stats, info: MachineInfo) -> Program:
    """Trace the job's bounding box in machine coordinates with the beam off (M5), then go back."""
    box = stats.burn_extent or stats.extent
    if box is None:
        raise InputError("the job does not move; nothing to frame")
    (x0, y0), (x1, y1) = box
    feed = min(DEFAULT_FRAME_FEED, info.settings.get(110, DEFAULT_FRAME_FEED),
               info.settings.get(111, DEFAULT_FRAME_FEED))
    lines = framing_lines((x0, y0, x1, y1), feed=feed, machine_coordinates=True, return_to=info.position[:2])
    return program_from_text("\n".join(lines), source="frame")


def _with_resume_hint(error: StreamError, program: Program) -> StreamError:
    """The same error, telling which --from-line picks up after the last acknowledged line."""
    later = [number for number, _ in program.lines if number > error.last_acked_line]
    if not error.last_acked_line or not later:
        return error
    hint = f"; to resume: --from-line {later[0]} (lines just after it may already have run)"
    return type(error)(str(error) + hint, last_acked_line=error.last_acked_line, failed_line=error.failed_line)


@contextlib.contextmanager
def _key_controls(streamer: GrblStreamer, enabled: bool):
    """Keys while streaming on a terminal: space/p pause, r resume, +/- feed, >/< power, q abort."""
    if not enabled:
        yield
        return
    import termios
    import tty

    fd = sys.stdin.fileno()
    saved = termios.tcgetattr(fd)
    stop = threading.Event()

    def loop() -> None:
        actions = {" ": streamer.pause, "p": streamer.pause, "r": streamer.resume, "q": streamer.abort,
                   "+": lambda: streamer.feed_override(10), "-": lambda: streamer.feed_override(-10),
                   ">": lambda: streamer.power_override(10), "<": lambda: streamer.power_override(-10)}
        while not stop.is_set():
            ready, _, _ = select.select([fd], [], [], 0.2)
            if ready:
                key = os.read(fd, 1).decode("latin-1").lower()
                if key in actions:
                    with contextlib.suppress(MachineError):
                        actions[key]()

    tty.setcbreak(fd)  # keeps ISIG: Ctrl-C still interrupts
    thread = threading.Thread(target=loop, name="stream-keys", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(timeout=1.0)
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def run_stream(gcode_path, *, port: str, baud: int = 115200, check: bool = False, frame: bool = False,
               profile: str | os.PathLike | None = None, from_line: int | None = None, reset: bool = True,
               allow_settings: bool = False, progress_every: float | None = None) -> None:
    """Connect to `port`, check the job against the machine, stream it with a progress bar
    and print a summary. `check` streams in GRBL's check mode ($C, nothing moves); `frame`
    only traces the job's bounding box with the beam off. `profile`: a laser profile TOML
    to compare with the machine's settings. `from_line`: resume at this file line (after a
    failure), moving there with the beam off first. `reset`: False attaches without a soft
    reset (refused while the controller runs a job). `allow_settings`: let `$` lines of the
    file through (otherwise the pre-check refuses them). `progress_every`: seconds between
    plain progress lines when the output is not a terminal (None: the CLI's pace, 5 s or
    ONESTROKE_PROGRESS_SECONDS). Raises OnestrokeError on any
    failure."""
    path = Path(gcode_path)
    if progress_every is None:
        progress_every = plain_progress_every()
    program = load_program(path)
    if from_line is not None:
        # The job's own start is the machine origin unless it moves there itself.
        program = resume_program(program, from_line)
        warn(f"resuming {path.name} at line {from_line}: lines before it are skipped; the head first moves "
             "there with the beam off - check that the workpiece has not moved")
    check_baud(baud)
    laser_profile = None
    if profile is not None:
        from machines.laser_profile import load_laser_profile

        laser_profile = load_laser_profile(profile)
    handle = open_port(port, baud=baud)
    time_scale = float(getattr(handle, "time_scale", 1.0))
    with GrblStreamer(handle, name=port) as streamer:
        console.print(f"connecting to {port} at {baud} baud ...")
        info = streamer.connect(reset=reset)
        if info.alarm:
            raise MachineError(f"{port} is locked in ALARM (it booted or was left in alarm): home it with $H, or "
                               "unlock it with $X if it has no homing switches, then run again")
        stats = analyze_program(program, settings=info.settings, start=info.position, offsets=info.offsets,
                                planner_blocks=info.planner_blocks, allow_settings=allow_settings)
        for problem in check_job(stats, info.settings, profile=laser_profile):
            if problem.fatal:
                raise InputError(f"{path.name}: {problem.message}")
            warn(problem.message)
        if frame:
            box = stats.burn_extent or stats.extent
            result = streamer.stream(_frame_program(stats, info))
            (x0, y0), (x1, y1) = box
            done(f"framed {x1 - x0:.1f} x {y1 - y0:.1f} mm at X{x0:.1f} Y{y0:.1f} (machine) with the beam off "
                 f"in {_format_seconds(result.elapsed)}")
            return
        machine = _machine_profile(info, laser_profile)
        job = estimate_program_time(program, machine, stats=stats)
        # cumulative seconds at the end of each streamed line (for the ETA)
        line_seconds = job.line_seconds[[max(0, number - 1) for number, _ in program.lines]]
        total = job.total_seconds
        sim = f" (simulated, {time_scale:g}x faster)" if time_scale != 1.0 else ""
        console.print(f"GRBL {info.version}: RX {info.rx_buffer} B, planner {info.planner_blocks} blocks; "
                      f"{len(program)} lines, estimated {_format_seconds(total)} of machine time{sim}, "
                      f"{job.bound_text(machine)}"
                      + (" - check mode, nothing moves" if check else ""))
        columns = (TextColumn("[bold]{task.description}"), BarColumn(),
                   TextColumn("{task.completed}/{task.total} lines"), TimeElapsedColumn(),
                   TextColumn("ETA {task.fields[eta]}"), TextColumn("{task.fields[state]}"))
        interactive = sys.stdin.isatty() and console.is_terminal
        with Progress(*columns, console=console.rich, transient=False, disable=not console.is_terminal) as bar:
            task = bar.add_task("check" if check else "stream", total=len(program), eta="-", state="")
            last = [0.0]
            plain_next = [time.monotonic() + progress_every]

            def on_progress(p: StreamProgress) -> None:
                now = time.monotonic()
                if now - last[0] < 0.1 and p.acked < p.total:
                    return
                last[0] = now
                remaining = (total - float(line_seconds[p.acked - 1])) / time_scale if p.acked else total
                eta = "-" if check else _format_seconds(remaining)
                bar.update(task, completed=p.acked, eta=eta, state=p.state or "")
                if not console.is_terminal and now >= plain_next[0]:
                    # piped or logged: one plain line every few seconds instead of a bar
                    plain_next[0] = now + progress_every
                    console.print(f"{p.acked}/{p.total} lines acknowledged ({100.0 * p.acked / max(1, p.total):.0f} %), "
                                  f"elapsed {_format_seconds(p.elapsed)}, remaining {eta}", highlight=False)

            if interactive:
                console.print("keys: space pause, r resume, +/- feed, </> power, q or Ctrl-C abort")
            with _key_controls(streamer, interactive):
                try:
                    result = streamer.stream(program, check=check, on_progress=on_progress)
                except StreamError as error:
                    raise _with_resume_hint(error, program) from None
        for message in result.warnings:
            warn(message)
        if check:
            if result.check_errors:
                line, text = result.check_errors[0]
                more = f" (and {len(result.check_errors) - 1} more)" if len(result.check_errors) > 1 else ""
                raise InputError(f"{path.name}: check mode: line {line} refused: {text}{more}")
            done(f"check passed: GRBL accepted all {len(program)} lines of {path.name} (nothing moved)")
            return
        extra = ""
        emu = getattr(handle, "emulator", None)
        if emu is not None:  # a sim:// dry run: the emulator's own planner time is the machine's
            stats = emu.stats()
            extra = (f"; dry run on the emulator at {time_scale:g}x, a machine would take about "
                     f"{_format_seconds(stats.planner_limited_time)}")
        elif time_scale != 1.0:
            extra = f"; {_format_seconds(result.elapsed * time_scale)} of machine time"
        done(f"streamed {len(program)} lines of {path.name} to {port} in {_format_seconds(result.elapsed)} "
             f"(estimate {_format_seconds(total)}{extra}); machine Idle, beam off")


@click.command("stream")
@input_argument("gcode")
@machine_options(port_required=True)
@click.option("--check", is_flag=True, help="Dry run in GRBL's check mode ($C): parse everything, move nothing.")
@click.option("--frame", is_flag=True, help="Only trace the job's bounding box with the beam off.")
@click.option("--no-reset", is_flag=True,
              help="Attach without resetting the controller (refused while it runs a job); default: soft reset.")
@click.option("--allow-settings", is_flag=True,
              help="Let '$' commands of the file through (e.g. $32=1); otherwise the pre-check refuses them.")
@click.option("--from-line", type=Integer(Range(1, 100_000_000)), default=None,
              help="Resume at this file line after a failure (the head moves there with the beam off).")
def stream(gcode: str, port: str, baud: int, check: bool, frame: bool, profile_path: str | None,
           no_reset: bool, allow_settings: bool, from_line: int | None) -> None:
    """Stream GCODE to a GRBL laser over USB serial (pause, resume and abort leave the beam off)."""
    if check and frame:
        raise InputError("--check and --frame cannot be combined: --frame only traces the bounding box; "
                         "run --check first, then --frame")
    run_stream(gcode, port=port, baud=baud, check=check, frame=frame, profile=profile_path, from_line=from_line,
               reset=not no_reset, allow_settings=allow_settings)


@click.command("emulator")
@click.option("--speed", type=Number(TIME_SCALE), default=1.0, show_default=True,
              help="Time scale, above 0 to 1000 (1 = a real machine's pace).")
@output_option(flags=("--log",), dest="log_path", required=False,
               help="On exit, write every line the emulator executed to this file.")
def emulator(speed: float, log_path: Path | None) -> None:
    """Serve a GRBL 1.1 emulator on a pseudo-terminal until Ctrl-C (for any sender, or tests)."""
    from machines.emulator import EmulatorOptions, GrblEmulator
    from onestroke.atomic import atomic_write_text

    emu = GrblEmulator(EmulatorOptions(time_scale=speed))
    device = emu.start_pty()
    click.echo(device)
    console.print(f"GRBL 1.1h emulator on {device} ({speed:g}x); Ctrl-C to stop")
    try:
        while True:
            time.sleep(0.5)
    except KeyboardInterrupt:
        pass
    finally:
        emu.stop()
        stats = emu.stats()
        if log_path is not None:
            atomic_write_text(log_path, "".join(line + "\n" for line in emu.executed))
        done(f"emulator: {stats.lines_executed} lines, {stats.blocks_executed} blocks, planner-limited "
             f"{_format_seconds(stats.planner_limited_time)}, RX overflow {stats.rx_overflow_bytes} B")
