"""Streaming G-code to GRBL 1.1 over a pyserial port, safely.

Character counting (grbl.md): a FIFO of the byte lengths of lines sent and not yet
answered; a line goes out only if it fits in the firmware's RX buffer; each `ok` or
`error:N` retires the oldest. EEPROM writers go one at a time (send-response). A reader
thread parses every reply, a poller thread asks `?` at up to 5 Hz. Whatever goes wrong
(error:N, ALARM, unreadable bytes, a lost `ok`, Ctrl-C) ends in `_halt`: feed hold, wait
for Hold:0, soft reset - the beam is off and no alarm is raised - and a `StreamError`
naming the last line the machine acknowledged.
"""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import serial

from machines.gcode_program import Program
from machines.grbl_codes import describe_alarm, describe_error
from machines.grbl_protocol import (CYCLE_START, DEFAULT_PLANNER_BLOCKS, DEFAULT_RX_BUFFER, FEED_HOLD,
                                    FEED_OV_MINUS_1, FEED_OV_MINUS_10, FEED_OV_PLUS_1, FEED_OV_PLUS_10,
                                    FEED_OV_RESET, SOFT_RESET, SPINDLE_OV_MINUS_1, SPINDLE_OV_MINUS_10,
                                    SPINDLE_OV_PLUS_1, SPINDLE_OV_PLUS_10, SPINDLE_OV_RESET, STATUS_QUERY,
                                    Alarm, ErrorReply, Message, Ok, Reply, Setting, StatusReport, Unknown,
                                    Welcome, is_alarm_lock_message, is_eeprom_writer, parse_options,
                                    parse_reply)
from onestroke.errors import MachineError

# Appended to every job: its `ok` only comes once the planner has drained, so the end of
# the job is known even when status reports carry no buffer counts ($10 without Bf).
DRAIN_LINE = "G4P0"


class StreamError(MachineError):
    """Streaming stopped. `last_acked_line` is the last file line GRBL acknowledged (0: none);
    `halt` how the machine was stopped (None when no halt was attempted)."""

    def __init__(self, message: str, *, last_acked_line: int = 0, failed_line: int | None = None,
                 halt: HaltReport | None = None):
        super().__init__(message)
        self.last_acked_line = last_acked_line
        self.failed_line = failed_line
        self.halt = halt


class StreamInterrupted(StreamError):
    """The user stopped the job (Ctrl-C or abort); the machine was halted safely."""

    exit_code = 130


@dataclass(frozen=True, kw_only=True)
class HaltReport:
    """How a halt went: feed holds sent (1, or 2 when the first got no Hold), seconds from
    the stop signal to the soft reset, and whether the controller confirmed the reset
    with its welcome (then the beam is off: a reset stops the spindle/laser)."""

    holds_sent: int
    reset_after: float
    confirmed: bool

    def describe(self) -> str:
        again = "feed hold sent twice (no Hold within 0.5 s), " if self.holds_sent > 1 else ""
        if self.confirmed:
            return f"{again}machine reset {self.reset_after:.2f} s after the stop, beam off"
        return (f"{again}reset sent {self.reset_after:.2f} s after the stop but not confirmed - check the machine and "
                "switch the laser off by hand")


@dataclass(frozen=True, kw_only=True)
class StreamOptions:
    """Timing of the sender, in seconds.

    connect_timeout: wait for the welcome after a soft reset. status_hz: `?` rate (GRBL
    asks for 5 Hz at most). watchdog: an Idle machine that leaves a line unanswered this
    long trips the stall / lost-ok watchdogs. hold_timeout: how long a hold nobody asked
    for may last mid-job before the sender gives up. send_response: send every line one
    at a time (slower; for comparison or odd firmware). hold_resend: when halting, send
    the feed hold again if no Hold was reported this long after the stop signal;
    reset_after: soft-reset this long after the stop signal at the latest (beam off).
    """

    connect_timeout: float = 5.0
    status_hz: float = 5.0
    watchdog: float = 2.0
    hold_timeout: float = 10.0
    send_response: bool = False
    hold_resend: float = 0.5
    reset_after: float = 0.9


@dataclass(frozen=True)
class MachineInfo:
    """What `connect` learned: firmware version, buffer sizes, `$$` settings ({N: value}),
    work offsets from `$#` ({"G54": (x, y, z), ..., "G92": ...}), machine position (mm),
    and whether the machine is locked in ALARM."""

    version: str
    rx_buffer: int
    planner_blocks: int
    settings: dict[int, float]
    offsets: dict[str, tuple[float, ...]]
    position: tuple[float, ...]
    alarm: bool


@dataclass(frozen=True)
class StreamProgress:
    """Progress after an answer: `acked` of `total` program lines, the file line number
    last acknowledged, seconds since the first line, latest state, stall recoveries."""

    acked: int
    total: int
    last_line: int
    elapsed: float
    state: str | None
    recoveries: int


@dataclass(frozen=True)
class StreamResult:
    """A finished stream. elapsed: seconds from the first line sent to Idle at the end."""

    lines: int
    elapsed: float
    mode: str
    recoveries: int
    check_errors: tuple[tuple[int, str], ...] = ()
    warnings: tuple[str, ...] = field(default=())


class _Disconnected:
    def __init__(self, error: Exception):
        self.error = error


class GrblStreamer:
    """A GRBL connection over an open pyserial port (device or URL such as `sim://`)."""

    def __init__(self, port: serial.SerialBase, *, name: str | None = None,
                 options: StreamOptions = StreamOptions()):
        self.port = port
        self.name = name or getattr(port, "port", None) or "the port"
        self.options = options
        self._replies: queue.Queue = queue.Queue()
        self._write_lock = threading.Lock()
        self._status_cond = threading.Condition()
        self._status: StatusReport | None = None
        self._status_time = 0.0
        self._running = True
        self._polling = False
        self._alarm_locked = False
        self._last_query = 0.0
        self._abort = threading.Event()
        self._abort_time = 0.0
        self._paused = False  # a hold the user asked for (pause) is not a stall
        self.rx_buffer = DEFAULT_RX_BUFFER
        self.planner_blocks = DEFAULT_PLANNER_BLOCKS
        self.warnings: list[str] = []
        self._reader = threading.Thread(target=self._read_loop, name="grbl-reader", daemon=True)
        self._poller = threading.Thread(target=self._poll_loop, name="grbl-status", daemon=True)
        self._reader.start()
        self._poller.start()

    # ------------------------------------------------------------------ threads

    def _read_loop(self) -> None:
        buffer = b""
        empty_reads = 0
        while self._running:
            try:
                data = self.port.read(self.port.in_waiting or 1)
                empty_reads = 0
            except (serial.SerialException, OSError, TypeError, AttributeError) as error:
                # "readiness to read but returned no data" also happens for a moment on a
                # pseudo-terminal whose other side is busy reopening; a real unplug repeats.
                if "returned no data" in str(error) and empty_reads < 10 and self._running:
                    empty_reads += 1
                    time.sleep(0.02)
                    continue
                if self._running:
                    self._replies.put(_Disconnected(error))
                return
            if not data:
                continue
            buffer += data
            while b"\n" in buffer:
                line, _, buffer = buffer.partition(b"\n")
                self._dispatch(line)
            if len(buffer) > 256:  # a flood with no line end: noise or a wrong baud rate
                self._dispatch(buffer)
                buffer = b""

    def _dispatch(self, line: bytes) -> None:
        line = line.rstrip(b"\r")
        if not line:
            return
        reply = parse_reply(line)
        if isinstance(reply, StatusReport):
            with self._status_cond:
                self._status, self._status_time = reply, time.monotonic()
                self._status_cond.notify_all()
            return
        if isinstance(reply, Alarm) or is_alarm_lock_message(reply):
            self._alarm_locked = True
        elif isinstance(reply, Welcome):
            self._alarm_locked = False
        self._replies.put(reply)

    @property
    def _query_period(self) -> float:
        return 1.0 / max(0.1, min(self.options.status_hz, 5.0))

    def _query_status(self) -> None:
        """Send `?` unless one went out less than a poll period ago (GRBL: at most 5 Hz)."""
        with self._write_lock:
            if time.monotonic() - self._last_query < self._query_period:
                return
            self._last_query = time.monotonic()
        self._write(STATUS_QUERY)

    def _poll_loop(self) -> None:
        while self._running:
            time.sleep(self._query_period / 4)
            if self._polling:
                try:
                    self._query_status()
                except MachineError:
                    return

    def _write(self, data: bytes) -> None:
        try:
            with self._write_lock:
                self.port.write(data)
        except (serial.SerialException, OSError) as error:
            raise MachineError(f"lost the connection to {self.name}: {error}") from None

    def close(self) -> None:
        """Stop the threads and close the port."""
        self._running = False
        self._polling = False
        try:
            self.port.close()
        except Exception:  # noqa: BLE001 - closing a dead port may fail in many ways
            pass
        for thread in (self._reader, self._poller):
            if thread is not threading.current_thread():
                thread.join(timeout=1.0)

    def __enter__(self) -> GrblStreamer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------------ status

    @property
    def status(self) -> StatusReport | None:
        """The latest status report (None before the first)."""
        return self._status

    def _next_reply(self, timeout: float) -> Reply | _Disconnected | None:
        try:
            return self._replies.get(timeout=timeout)
        except queue.Empty:
            return None

    def wait_status(self, predicate: Callable[[StatusReport], bool], timeout: float) -> StatusReport | None:
        """Poll `?` (at most 5 Hz) until a new report satisfies `predicate`; None on timeout."""
        deadline = time.monotonic() + timeout
        seen = self._status_time
        while time.monotonic() < deadline:
            self._query_status()
            with self._status_cond:
                self._status_cond.wait_for(lambda: self._status_time > seen, timeout=0.05)
                if self._status_time > seen:
                    seen = self._status_time
                    if predicate(self._status):
                        return self._status
        return None

    # ------------------------------------------------------------------ connect

    def connect(self, *, reset: bool = True) -> MachineInfo:
        """Soft-reset, wait for the welcome, then read `$I`, `$$`, `$#` and the position.

        reset: False attaches without resetting (a reset would kill a job another program
        started): it asks for a status first and refuses a controller that is busy
        (Run, Hold, Jog, Home, Door) - streaming into a running job would mix two jobs.
        """
        try:
            self.port.reset_input_buffer()
        except (serial.SerialException, OSError):
            pass
        self._drain_replies()
        if reset:
            version = self._reset_and_greet()
        else:
            version = self._attach()
        for reply in self._optional("$I"):  # without [OPT:...] the GRBL 1.1 sizes hold
            if isinstance(reply, Message) and reply.kind == "OPT":
                self.planner_blocks, self.rx_buffer = parse_options(reply.text)
            elif isinstance(reply, Message) and reply.kind == "VER" and version is None:
                version = reply.text.split(":")[0].rsplit(".", 1)[0]
        settings = {r.number: r.value for r in self._collect("$$") if isinstance(r, Setting)}
        offsets = {}
        for reply in self._optional("$#"):
            if isinstance(reply, Message) and reply.kind.startswith("G") and reply.kind[1:3].isdigit():
                try:
                    offsets[reply.kind] = tuple(float(v) for v in reply.text.split(":")[0].split(","))
                except ValueError:
                    pass
        status = self.wait_status(lambda s: True, timeout=2.0)
        position = (0.0, 0.0, 0.0)
        if status is not None and status.mpos is not None:
            position = status.mpos
        elif status is not None and status.wpos is not None:
            wco = offsets.get("G54", (0.0, 0.0, 0.0))
            position = tuple(w + o for w, o in zip(status.wpos, wco))
        alarm = self._alarm_locked or (status is not None and status.state == "Alarm")
        return MachineInfo(version or "1.1", self.rx_buffer, self.planner_blocks, settings, offsets,
                           tuple(position), alarm)

    def _reset_and_greet(self) -> str:
        """Soft reset and the welcome that answers it; returns the firmware version."""
        self._write(SOFT_RESET)
        welcome = self._wait_welcome(self.options.connect_timeout)
        if welcome is None:
            raise MachineError(
                f"no answer from {self.name} within {self.options.connect_timeout:g} s: not a GRBL board, "
                "wrong baud rate (--baud), or still booting; check the cable and 'onestroke ports'; "
                "nothing was sent, no line was acknowledged")
        # A board that reboots when the port opens may greet twice (its boot, then our
        # reset); a reset arriving after the next command would swallow it, so wait it out.
        while (again := self._wait_welcome(0.3)) is not None:
            welcome = again
        if welcome.version.startswith("0."):
            raise MachineError(f"{self.name} runs GRBL {welcome.version}; onestroke speaks GRBL 1.1 (status "
                               "reports and real-time commands differ): update the firmware to 1.1")
        return welcome.version

    def _attach(self) -> str | None:
        """Attach without a reset: status first; refuse a controller that is busy."""
        status = self.wait_status(lambda s: True, self.options.connect_timeout)
        if status is None:
            raise MachineError(
                f"no status from {self.name} within {self.options.connect_timeout:g} s (attaching without a "
                "reset): not a GRBL 1.1 board, wrong baud rate (--baud), or still booting; nothing was sent")
        if status.state in ("Run", "Hold", "Jog", "Home", "Door"):
            raise MachineError(
                f"{self.name} is busy ({status.full_state}): another program's job is running; onestroke does not "
                "stream into a running job - wait for it to end (or stop it there), then run again")
        self._drain_replies()
        return None

    def _optional(self, line: str) -> list[Reply]:
        """Replies to an informational command, or none if this firmware refuses it."""
        try:
            return self._collect(line)
        except MachineError as error:
            if "refused" not in str(error):
                raise
            return []

    def _drain_replies(self) -> list[Reply]:
        drained = []
        while True:
            try:
                drained.append(self._replies.get_nowait())
            except queue.Empty:
                return drained

    def _wait_welcome(self, timeout: float) -> Welcome | None:
        deadline = time.monotonic() + timeout
        while (left := deadline - time.monotonic()) > 0:
            reply = self._next_reply(min(left, 0.1))
            if isinstance(reply, _Disconnected):
                raise MachineError(f"lost the connection to {self.name}: {reply.error}")
            if isinstance(reply, Welcome):
                return reply
        return None

    def _collect(self, line: str, timeout: float = 5.0) -> list[Reply]:
        """Send-response: send `line`, return the replies up to its `ok`; raise on `error:N`."""
        self._write(line.encode("ascii") + b"\n")
        replies: list[Reply] = []
        deadline = time.monotonic() + timeout
        while (left := deadline - time.monotonic()) > 0:
            reply = self._next_reply(min(left, 0.1))
            if reply is None or isinstance(reply, Unknown):
                continue
            if isinstance(reply, _Disconnected):
                raise MachineError(f"lost the connection to {self.name}: {reply.error}")
            if isinstance(reply, Ok):
                return replies
            if isinstance(reply, ErrorReply):
                raise MachineError(f"GRBL refused {line!r}: {describe_error(reply.code)}")
            if isinstance(reply, Alarm):
                raise MachineError(f"{describe_alarm(reply.code)} (while sending {line!r})")
            replies.append(reply)
        raise MachineError(f"no answer to {line!r} from {self.name} within {timeout:g} s")

    def command(self, line: str, timeout: float = 5.0) -> list[Reply]:
        """Send one line and wait for its answer (for `$` commands and EEPROM writes)."""
        return self._collect(line, timeout)

    # ------------------------------------------------------------------ real-time controls

    def pause(self) -> None:
        """Feed hold (`!`): decelerate to a stop; the beam goes off in laser mode (M4)."""
        self._paused = True
        self._write(FEED_HOLD)

    def resume(self, timeout: float = 10.0) -> None:
        """Cycle start (`~`) once the hold is complete (GRBL ignores `~` while decelerating)."""
        self.wait_status(lambda s: s.full_state != "Hold:1", timeout)
        self._write(CYCLE_START)
        self._paused = False

    def abort(self) -> None:
        """Ask the running `stream` to stop safely (from another thread); it raises StreamInterrupted."""
        self._abort_time = time.monotonic()
        self._abort.set()

    def feed_override(self, step: int) -> None:
        """Feed override: +10/-10/+1/-1 percent, or 0 to reset to 100 % (10-200 %)."""
        self._write({10: FEED_OV_PLUS_10, -10: FEED_OV_MINUS_10, 1: FEED_OV_PLUS_1, -1: FEED_OV_MINUS_1,
                     0: FEED_OV_RESET}[step])

    def power_override(self, step: int) -> None:
        """Laser power (spindle) override: +10/-10/+1/-1 percent, or 0 to reset (10-200 %)."""
        self._write({10: SPINDLE_OV_PLUS_10, -10: SPINDLE_OV_MINUS_10, 1: SPINDLE_OV_PLUS_1,
                     -1: SPINDLE_OV_MINUS_1, 0: SPINDLE_OV_RESET}[step])

    def halt(self, since: float | None = None) -> HaltReport:
        """Stop safely now: `!`; `!` again if no Hold is reported within `hold_resend`
        seconds of `since` (the stop signal; default now); soft reset once the hold is
        complete and in any case `reset_after` seconds after `since`; wait for the welcome.

        A reset after a completed hold raises no alarm; any reset turns the beam off.
        """
        since = time.monotonic() if since is None else since
        holds = 0

        def left(limit: float) -> float:
            return max(0.0, since + limit - time.monotonic())

        try:
            self._write(FEED_HOLD)
            holds = 1
            stopped = ("Hold:0", "Idle", "Alarm", "Check", "Sleep")
            seen = self.wait_status(lambda s: s.state in ("Hold", *stopped), left(self.options.hold_resend))
            if seen is None:
                self._write(FEED_HOLD)  # the first one was lost (noise) or came too early
                holds = 2
            if seen is None or seen.full_state not in stopped:
                self.wait_status(lambda s: s.full_state in stopped, left(self.options.reset_after))
            self._drain_replies()
            self._write(SOFT_RESET)
            reset_after = time.monotonic() - since
            confirmed = self._wait_welcome(self.options.connect_timeout) is not None
        except MachineError:
            return HaltReport(holds_sent=holds, reset_after=time.monotonic() - since, confirmed=False)
        return HaltReport(holds_sent=holds, reset_after=reset_after, confirmed=confirmed)

    # ------------------------------------------------------------------ streaming

    def stream(self, program: Program, *, check: bool = False,
               on_progress: Callable[[StreamProgress], None] | None = None) -> StreamResult:
        """Send every line of `program`; return when the machine is Idle again.

        check: run in GRBL's check mode (`$C`): everything is parsed, nothing moves, and
        refused lines are collected instead of stopping the job.
        """
        if self._alarm_locked:
            raise StreamError(f"{self.name} is locked in ALARM: home it with $H, or unlock it with $X if it has "
                              "no homing switches (onestroke does not unlock a machine by itself)")
        if check:
            replies = self.command("$C")
            if not any(isinstance(r, Message) and "Enabled" in r.text for r in replies):
                raise MachineError(f"{self.name} did not enter check mode ($C)")
        lines = list(program.lines) + [(0, DRAIN_LINE)]
        try:
            result = self._stream_lines(lines, check=check, on_progress=on_progress, total=len(program))
        finally:
            self._polling = False
        if check:
            self._write(b"$C\n")  # leaving check mode soft-resets GRBL
            if self._wait_welcome(self.options.connect_timeout) is None:
                raise MachineError(f"{self.name} did not leave check mode")
        return result

    def _stream_lines(self, lines: list[tuple[int, str]], *, check: bool, total: int,
                      on_progress: Callable[[StreamProgress], None] | None) -> StreamResult:
        rx = self.rx_buffer
        inflight: deque[tuple[int, int, bool]] = deque()  # (index in lines, bytes, send-response)
        used = 0
        sent = acked = 0
        last_line = 0
        recoveries = 0
        check_errors: list[tuple[int, str]] = []
        self._drain_replies()
        self._abort.clear()
        self._polling = True
        started = time.monotonic()
        last_answer = started
        resumed_since_answer = False
        mode = "send-response" if self.options.send_response else "character-counting"

        def stop(message: str, *, failed: int | None = None, halt: bool = True,
                 cls: type[StreamError] = StreamError, since: float | None = None) -> StreamError:
            since = time.monotonic() if since is None else since
            report = self.halt(since) if halt else None
            self._polling = False
            suffix = report.describe() if report is not None else ""
            where = f"last acknowledged line {last_line}" if last_line else "no line was acknowledged"
            text = "; ".join(part for part in (message, suffix, where) if part)
            return cls(text, last_acked_line=last_line, failed_line=failed, halt=report)

        try:
            while acked < len(lines):
                if self._abort.is_set():
                    raise stop("stopped on request", cls=StreamInterrupted, since=self._abort_time)
                # Send every line that fits in GRBL's RX buffer.
                while sent < len(lines):
                    number, text = lines[sent]
                    data = text.encode("ascii") + b"\n"
                    one_by_one = self.options.send_response or is_eeprom_writer(text)
                    if inflight and (one_by_one or inflight[-1][2]):
                        break  # EEPROM writes block GRBL's serial input: nothing else in flight
                    if used + len(data) > rx:
                        break
                    self._write(data)
                    inflight.append((sent, len(data), one_by_one))
                    used += len(data)
                    sent += 1
                reply = self._next_reply(0.1)
                now = time.monotonic()
                if reply is None:
                    if inflight:
                        if self._watchdog(lines, inflight, now - last_answer, resumed_since_answer, stop):
                            resumed_since_answer = True
                            last_answer = now
                    continue
                if isinstance(reply, _Disconnected):
                    buffered = len(inflight)
                    raise stop(f"lost the connection to {self.name} ({reply.error}); the machine may still run "
                               f"the {buffered} line(s) it had buffered - switch it off or reconnect and reset",
                               halt=False)
                if isinstance(reply, (Ok, ErrorReply)):
                    if not inflight:
                        raise stop(f"unexpected answer {reply} with no line in flight (another program on "
                                   f"{self.name}?)")
                    index, nbytes, _ = inflight.popleft()
                    used -= nbytes
                    number, text = lines[index]
                    if isinstance(reply, ErrorReply):
                        if check and number:
                            check_errors.append((number, f"{text}: {describe_error(reply.code)}"))
                        else:
                            where = f"line {number}" if number else "resume preamble line"
                            raise stop(f"{where} {text!r} was refused: {describe_error(reply.code)}",
                                       failed=number)
                    acked += 1
                    last_line = number or last_line
                    last_answer = now
                    if resumed_since_answer:  # the cycle start got it going again
                        recoveries += 1
                        self.warnings.append(f"the machine stalled Idle with moves queued near line {number}; "
                                             "restarted it with a cycle start (~)")
                    resumed_since_answer = False
                    if on_progress is not None:
                        on_progress(StreamProgress(min(acked, total), total, last_line, now - started,
                                                   self._status.full_state if self._status else None,
                                                   recoveries))
                elif isinstance(reply, Alarm):
                    failed = lines[inflight[0][0]][0] if inflight else None
                    raise stop(f"{describe_alarm(reply.code)}; stopped near line {failed}", failed=failed)
                elif isinstance(reply, Welcome):
                    raise stop(f"{self.name} restarted in the middle of the job (reset button, power dip or "
                               "a second program resetting it); its buffers are lost", halt=False)
                elif isinstance(reply, Unknown):
                    raise stop(f"unreadable bytes from {self.name}: {reply.raw[:24]!r} (electrical noise, a bad "
                               "USB cable or a wrong --baud); the answers can no longer be trusted")
            # Every line is answered, and GRBL answers the drain line (G4P0) only once the
            # planner is empty and the machine Idle: the job is done.
            if self._alarm_locked:
                raise stop("the machine went into ALARM at the end of the job")
        except KeyboardInterrupt:
            raise stop("stopped by Ctrl-C", cls=StreamInterrupted, since=time.monotonic()) from None
        except MachineError as error:
            if isinstance(error, StreamError):
                raise
            raise stop(str(error), halt=False) from None
        except Exception as error:  # a bug must not leave the machine burning: halt first
            raise stop(f"internal error {type(error).__name__}: {error}") from error
        elapsed = time.monotonic() - started
        return StreamResult(total, elapsed, mode, recoveries, tuple(check_errors), tuple(self.warnings))

    def _watchdog(self, lines, inflight, silent_for: float, resumed: bool, stop) -> bool:
        """Act on a machine that went quiet; True if a recovery was attempted."""
        limit = self.options.watchdog + sum(_dwell_seconds(lines[i][1]) for i, _, _ in inflight)
        if silent_for < limit:
            return False
        status, seen = self._status, self._status_time
        if status is None or time.monotonic() - seen > max(2.0, limit):
            raise stop(f"{self.name} stopped answering (no status report for {time.monotonic() - seen:.1f} s)",
                       failed=lines[inflight[0][0]][0])
        if status.state == "Alarm":
            # An ALARM whose message did not reach us: nothing will run until $X / $H.
            raise stop(f"{self.name} is in ALARM and answers nothing; unlock with $X or home with $H",
                       failed=lines[inflight[0][0]][0])
        if status.state in ("Run", "Jog", "Home") or (status.state == "Hold" and self._paused):
            return False  # running a long move, homing, or paused by the user: not stuck
        if status.state != "Idle":
            # A hold nobody asked for, a door, sleep: give it the hold timeout, then stop
            # rather than wait forever.
            if silent_for < limit + self.options.hold_timeout:
                return False
            raise stop(f"{self.name} stays in {status.full_state} with line {lines[inflight[0][0]][0]} "
                       "unanswered", failed=lines[inflight[0][0]][0])
        number, text = lines[inflight[0][0]]
        queued = status.planner_free is not None and status.planner_free < self.planner_blocks
        if queued or (status.planner_free is None and not resumed):
            # GRBL can go Idle with blocks queued and never restart by itself; `~` recovers.
            self._write(CYCLE_START)
            return True
        raise stop(f"no answer to line {number} {text!r} for {silent_for:.1f} s while the machine is Idle with "
                   "nothing left to do: an 'ok' was lost (electrical noise?), so the line count can no longer "
                   "be trusted", failed=number)


def _dwell_seconds(text: str) -> float:
    """Seconds of a G4 dwell in a cleaned line (0 if none): its `ok` comes only afterwards."""
    if "G4" not in text or "P" not in text:
        return 0.0
    try:
        return float(text.split("P", 1)[1].split("G")[0].split("M")[0])
    except ValueError:
        return 0.0
