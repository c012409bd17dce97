"""Streaming G-code to GRBL 1.1 over a pyserial port, safely: the connection's threads
and the streaming loop.

Character counting (grbl.md): a FIFO of the byte lengths of lines sent and not yet
answered; a line goes out only if it fits in the firmware's RX buffer; each `ok` or
`error:N` retires the oldest. EEPROM writers go one at a time (send-response). A reader
thread parses every reply, a poller thread asks `?` at up to 5 Hz. Whatever goes wrong
(error:N, ALARM, unreadable bytes, a lost `ok`, Ctrl-C) ends in `halt`: feed hold, wait
for Hold:0, soft reset - the beam is off and no alarm is raised - and a `StreamError`
naming the last line the machine acknowledged.

The other parts of `GrblStreamer`: `stream_connect` (reset or attach, `$` commands),
`stream_stops` (real-time controls, halt, watchdog), `stream_types` (options, results,
errors; re-exported here).
"""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from collections.abc import Callable

import serial

from machines.gcode_program import Program
from machines.grbl_codes import describe_alarm, describe_error
from machines.grbl_protocol import (DEFAULT_PLANNER_BLOCKS, DEFAULT_RX_BUFFER, STATUS_QUERY, Alarm, ErrorReply,
                                    Message, Ok, Reply, StatusReport, Unknown, Welcome, is_alarm_lock_message,
                                    is_eeprom_writer, parse_reply)
from machines.stream_connect import StreamConnect
from machines.stream_stops import StreamStops
from machines.stream_types import (DRAIN_LINE, Disconnected, HaltReport, MachineInfo, StreamError, StreamInterrupted,
                                   StreamOptions, StreamProgress, StreamResult)
from onestroke.errors import MachineError

__all__ = ["DRAIN_LINE", "GrblStreamer", "HaltReport", "MachineInfo", "StreamError", "StreamInterrupted",
           "StreamOptions", "StreamProgress", "StreamResult"]


class GrblStreamer(StreamConnect, StreamStops):
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
                    self._replies.put(Disconnected(error))
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
                if not self.port.is_open:  # closed by close() while the poller was on its way
                    raise serial.PortNotOpenError()
                self.port.write(data)
        except (serial.SerialException, OSError) as error:
            raise MachineError(f"lost the connection to {self.name}: {error}") from None

    def close(self) -> None:
        """Stop the threads and close the port."""
        self._running = False
        self._polling = False
        try:
            with self._write_lock:  # no write can be half way through the port as it closes
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

    def _next_reply(self, timeout: float) -> Reply | Disconnected | None:
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
        # A line longer than GRBL's receive buffer never fits, whatever has been answered:
        # character counting would wait for room forever. Refused before anything is sent.
        for number, text in lines:
            if len(text) + 1 > self.rx_buffer:
                raise StreamError(f"line {number} is {len(text) + 1} bytes with its newline, more than the "
                                  f"{self.rx_buffer}-byte receive buffer of {self.name}: GRBL can never take it; "
                                  "nothing was sent", failed_line=number)
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

        def stop(message: str, **how) -> StreamError:
            return self._stop_error(message, last_line=last_line, **how)

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
                if isinstance(reply, Disconnected):
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
        except KeyboardInterrupt as signal:  # Ctrl-C; SIGTERM and SIGHUP come as onestroke.errors.Interrupted
            raise stop(f"stopped by {str(signal) or 'Ctrl-C'}", cls=StreamInterrupted, since=time.monotonic()) from None
        except MachineError as error:
            if isinstance(error, StreamError):
                raise
            raise stop(str(error), halt=False) from None
        except Exception as error:  # a bug must not leave the machine burning: halt first
            raise stop(f"internal error {type(error).__name__}: {error}") from error
        elapsed = time.monotonic() - started
        return StreamResult(total, elapsed, mode, recoveries, tuple(check_errors), tuple(self.warnings))
