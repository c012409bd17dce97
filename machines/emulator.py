"""A GRBL 1.1 emulator that speaks the serial protocol on a pseudo-terminal.

It models what matters to a sender: a 128-byte RX buffer fed at the wire rate that DROPS
overflow bytes like the firmware's serial interrupt; a parse time per line; a 15-block
planner whose motion takes the time GRBL's planner rules give (see `planner_model`);
real-time bytes (status, hold, resume, reset, overrides); check mode; the common errors
and alarms; and a log of every line it executed. `time_scale` > 1 runs everything (wire,
parsing, motion) that many times faster than a real machine.

Use it in-process (`GrblEmulator(...).start_pty()` returns a device path for pyserial),
through pyserial as `sim://` (see `machines.sim_url`), or from a shell:
`onestroke emulator` prints a device path for any sender.
"""

from __future__ import annotations

import dataclasses
import errno
import os
import select
import threading
import time
import tty
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from machines.gcode_interpreter import GcodeError, GcodeInterpreter, MachineConfig
from machines.grbl_protocol import MAX_LINE_CHARS, clean_line
from machines.grbl_settings import FIRMWARE_DEFAULTS, INTEGER_SETTINGS, settings_from_profile
from machines.laser_profile import load_laser_profile
from machines.planner_model import Block, BlockBuilder, Kinematics, exit_speed, plan_times, trapezoid

VERSION = "1.1h"
BUILD_DATE = "20190825"

def _default_settings() -> dict[int, float]:
    # The emulated machine is the default laser profile's machine (profiles are data).
    try:
        return settings_from_profile(load_laser_profile())
    except Exception:  # noqa: BLE001 - a broken profile file must not break the emulator
        return dict(FIRMWARE_DEFAULTS)


DEFAULT_SETTINGS: dict[int, float] = _default_settings()


@dataclass(frozen=True, kw_only=True)
class Faults:
    """Faults to inject, counted in G-code lines executed (1 = the first program line).

    silent: never answer anything (a dead board, another device, a wrong baud rate).
    drop_ok_at: that line's `ok` is never sent (a byte lost to electrical noise).
    stall_at: after that line the machine goes Idle with blocks queued until `~`.
    garbage_at: after that line's `ok`, noise bytes appear on the line.
    disconnect_at: after that line the port disappears (USB unplugged; board unpowered).
    alarm_at: that line trips a limit switch: ALARM:1, motion stops, beam off.
    error_at: that line is answered with error:20 whatever it contains.
    drop_hold: that many feed-hold bytes (`!`) are lost on the way (noise, a busy adapter).
    """

    silent: bool = False
    drop_ok_at: int | None = None
    stall_at: int | None = None
    garbage_at: int | None = None
    disconnect_at: int | None = None
    alarm_at: int | None = None
    error_at: int | None = None
    drop_hold: int = 0


@dataclass(frozen=True, kw_only=True)
class EmulatorOptions:
    """How the emulated machine behaves.

    time_scale: speed-up over a real machine (wire, parsing and motion all scale).
    baud: wire rate in bit/s (10 bits a byte), both ways. usb_latency: seconds a USB-serial
    adapter adds in each direction (about 1 ms a round trip). parse_time: seconds a line takes to parse
    and plan on the AVR (GRBL parses about 500 lines/s). eeprom_write_time: seconds during
    which incoming bytes are lost after an EEPROM write. settings: $N values replacing
    `DEFAULT_SETTINGS`. boot_alarm: power up locked in ALARM (also when $22=1).
    """

    time_scale: float = 1.0
    baud: int = 115200
    usb_latency: float = 0.0005
    parse_time: float = 0.002
    eeprom_write_time: float = 0.017
    rx_buffer: int = 128
    planner_blocks: int = 15
    settings: Mapping[int, float] = field(default_factory=dict)
    boot_alarm: bool = False
    faults: Faults = Faults()


@dataclass(frozen=True)
class EmulatorStats:
    """What the emulator measured. Times are machine seconds (wall time x time_scale).

    planner_limited_time: the motion time if the planner had never been starved (each
    block planned with the full look-ahead), from the blocks actually executed.
    motion_time: from the first block's start to the last block's end, as it ran.
    """

    lines_executed: int
    blocks_executed: int
    planner_limited_time: float
    motion_time: float
    rx_overflow_bytes: int
    eeprom_lost_bytes: int
    max_rx_used: int
    state: str
    spindle: str
    spindle_s: float
    resets: int
    alarms: tuple[int, ...]


class _Reset(Exception):
    """Raised inside the protocol thread when a soft reset arrived."""


@dataclass
class _Planned:
    block: Block
    start: np.ndarray
    target: np.ndarray
    line_index: int
    mode: str
    s: float


class GrblEmulator:
    """GRBL 1.1 on a file descriptor (the master side of a pty)."""

    def __init__(self, options: EmulatorOptions = EmulatorOptions()):
        self.options = options
        self.settings: dict[int, float] = {**DEFAULT_SETTINGS, **dict(options.settings)}
        self.scale = float(options.time_scale)
        self.executed: list[str] = []  # every program line executed, cleaned, in order
        self.commands: list[str] = []  # '$' system lines
        self.spindle_history: list[tuple[str, float]] = []
        self.alarms: list[int] = []
        self.hold_times: list[float] = []  # time.monotonic() of each feed hold received
        self.reset_times: list[float] = []  # ... and of each soft reset received
        self._holds_to_drop = options.faults.drop_hold
        self._cond = threading.Condition()
        self._write_lock = threading.Lock()
        self._out_cond = threading.Condition()
        self._outbox: deque[tuple[float, bytes]] = deque()
        self._out_free = 0.0
        self._fd: int | None = None
        self._slave_fd: int | None = None
        self.device: str | None = None
        self._threads: list[threading.Thread] = []
        self._stopping = False
        self.disconnected = False
        self._reset_state(power_up=True)

    # ------------------------------------------------------------------ lifecycle

    def _reset_state(self, *, power_up: bool = False) -> None:
        kin = Kinematics.from_settings(self.settings, planner_blocks=self.options.planner_blocks)
        self.kin = kin
        self.config = MachineConfig(laser_mode=bool(self.settings[32]), soft_limits=bool(self.settings[20]),
                                    max_travel=(self.settings[130], self.settings[131], self.settings[132]),
                                    arc_tolerance=self.settings[12])
        if power_up:
            self.interp = GcodeInterpreter(self.config)
            self.position = np.zeros(3)
            self.rx = bytearray()
            self.planner: deque[_Planned] = deque()
            self.alarm = self.options.boot_alarm or bool(self.settings[22])
            self.program_lines = 0
            self.blocks_done = 0
            self.rx_overflow = 0
            self.eeprom_lost = 0
            self.max_rx = 0
            self.resets = 0
            # every move executed, for the planner-limited time: (start, target, feed, rapid, stop)
            self._ref_moves: list[tuple] = []
            self._ref_dwell = 0.0
            self._ref_rest = True
            self._first_motion: float | None = None
            self._last_motion: float | None = None
        else:
            self.interp.config = self.config
            self.interp.reset_modal()
        self._builder = BlockBuilder(kin)
        self.check_mode = False
        self.critical = False
        self.hold = False  # feed hold requested
        self.hold_complete = False
        self.stalled = False
        self._stall_pending = False
        self._reset_pending = False
        self._reset_was_moving = False
        self._adding = False
        self._current: tuple | None = None  # (planned, profile, t0)
        self._motion_busy = False
        self.spindle_mode, self.spindle_s = "M5", 0.0
        self.coolant: frozenset = frozenset()
        self.feed_ov, self.rapid_ov, self.spindle_ov = 100, 100, 100
        self._eeprom_until = 0.0
        self._status_count = 0
        self._homing = False

    def start_pty(self) -> str:
        """Open a pseudo-terminal, serve GRBL on it, and return the device path for the host."""
        master, slave = os.openpty()
        tty.setraw(slave)  # no echo, no line editing: a plain byte pipe like a UART
        self._slave_fd = slave
        self.device = os.ttyname(slave)
        self.attach(master)
        return self.device

    def attach(self, fd: int) -> None:
        """Serve GRBL on an already open file descriptor (threads start now)."""
        os.set_blocking(fd, False)
        self._fd = fd
        for target, name in ((self._reader_loop, "rx"), (self._protocol_loop, "protocol"),
                             (self._motion_loop, "motion"), (self._writer_loop, "tx")):
            thread = threading.Thread(target=target, name=f"grbl-emu-{name}", daemon=True)
            self._threads.append(thread)
            thread.start()

    def stop(self) -> None:
        """Stop the threads and close the pty."""
        with self._cond:
            self._stopping = True
            self._cond.notify_all()
        with self._out_cond:
            self._out_cond.notify_all()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(timeout=2.0)
        self._close_fds()

    def _close_fds(self) -> None:
        """Close both ends of the pty (once; later calls do nothing)."""
        for fd in (self._fd, self._slave_fd):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._fd = self._slave_fd = None

    def __enter__(self) -> GrblEmulator:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    # ------------------------------------------------------------------ observation

    @property
    def state(self) -> str:
        """The state word GRBL would report now (Idle, Run, Hold:0/1, Alarm, Check, Home)."""
        if self.alarm or self.critical:
            return "Alarm"
        if self._homing:
            return "Home"
        if self.check_mode:
            return "Check"
        if self.hold:
            return "Hold:0" if self.hold_complete else "Hold:1"
        if self.stalled:
            return "Idle"
        if self.planner or self._motion_busy:
            return "Run"
        return "Idle"

    @property
    def beam_on(self) -> bool:
        """True while the laser would be emitting (or would, on the next G1 move)."""
        return self.spindle_mode != "M5" and self.spindle_s > 0 and not self.disconnected

    def stats(self) -> EmulatorStats:
        """A snapshot of the counters; the planner-limited time is computed here."""
        with self._cond:
            moves = list(self._ref_moves)
            dwell = self._ref_dwell
            motion = 0.0
            if self._first_motion is not None and self._last_motion is not None:
                motion = float(self._last_motion - self._first_motion) * self.scale
            result = dict(lines_executed=len(self.executed), blocks_executed=self.blocks_done,
                          motion_time=motion, rx_overflow_bytes=self.rx_overflow,
                          eeprom_lost_bytes=self.eeprom_lost, max_rx_used=self.max_rx, state=self.state,
                          spindle=self.spindle_mode, spindle_s=self.spindle_s, resets=self.resets,
                          alarms=tuple(self.alarms))
        limited = dwell
        if moves:
            start, end, feed, rapid, stop = (np.array(column) for column in zip(*moves))
            limited += float(plan_times(start, end, feed.astype(float), rapid, stop, self.kin).sum())
        return EmulatorStats(planner_limited_time=limited, **result)

    def wait_until(self, predicate, timeout: float = 10.0) -> bool:
        """Block until predicate() holds (checked whenever the emulator's state changes); False on timeout."""
        with self._cond:
            return self._cond.wait_for(predicate, timeout)

    def wait_idle(self, timeout: float = 10.0) -> bool:
        """Block until the planner is empty and nothing moves; False on timeout."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while self.planner or self._motion_busy:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(left)
        return True

    # ------------------------------------------------------------------ output

    def _send(self, text: str | bytes) -> None:
        """Queue bytes for the host; they arrive after the USB latency and their wire time."""
        if self.options.faults.silent or self._fd is None:
            return
        data = text.encode("ascii") if isinstance(text, str) else text
        byte_time = 10.0 / self.options.baud / self.scale
        with self._out_cond:
            start = max(time.monotonic() + self.options.usb_latency / self.scale, self._out_free)
            self._out_free = start + len(data) * byte_time
            self._outbox.append((self._out_free, data))
            self._out_cond.notify()

    def _writer_loop(self) -> None:
        while True:
            with self._out_cond:
                while not self._outbox and not self._stopping:
                    self._out_cond.wait(0.05)
                if self._stopping and not self._outbox:
                    return
                due, data = self._outbox[0]
                wait = due - time.monotonic()
                if wait > 0:
                    self._out_cond.wait(wait)
                    continue
                self._outbox.popleft()
            with self._write_lock:
                while data and self._fd is not None:
                    try:
                        data = data[os.write(self._fd, data):]
                    except BlockingIOError:
                        time.sleep(0.001)  # host not reading yet: the pty holds 4 KB, wait
                    except (OSError, TypeError):
                        break

    def _reply(self, line: str) -> None:
        self._send(line + "\r\n")

    # ------------------------------------------------------------------ RX path (the ISR)

    def _reader_loop(self) -> None:
        byte_time = 10.0 / self.options.baud / self.scale
        pending = bytearray()
        wire_t = 0.0
        while not self._stopping and self._fd is not None:
            now = time.monotonic()
            if pending:
                wait = max(0.0003, min(wire_t + byte_time * min(len(pending), 16) - now, 0.05))
            else:
                wait = 0.05
            fd = self._fd
            if fd is None:
                return
            try:
                ready, _, _ = select.select([fd], [], [], wait)
            except (OSError, ValueError, TypeError):
                return
            if ready:
                try:
                    data = os.read(fd, 4096)
                except BlockingIOError:
                    data = b""
                except (TypeError, ValueError):
                    return
                except OSError as error:
                    if error.errno == errno.EIO:  # no host has the port open
                        time.sleep(0.01)
                        continue
                    return
                if data:
                    if not pending:  # a new burst: the USB adapter delivers it after its latency
                        wire_t = max(wire_t, time.monotonic() + self.options.usb_latency / self.scale)
                    pending += data
            if pending:
                now = time.monotonic()
                count = min(len(pending), int((now - wire_t) / byte_time))
                if count > 0:
                    chunk = bytes(pending[:count])
                    del pending[:count]
                    wire_t += count * byte_time
                    self._deliver(chunk, now)

    def _deliver(self, chunk: bytes, now: float) -> None:
        with self._cond:
            notify = False
            for byte in chunk:
                if byte in (0x18, 0x3F, 0x7E, 0x21) or byte >= 0x80:
                    self._realtime(byte)
                    continue
                if now < self._eeprom_until:
                    self.eeprom_lost += 1  # interrupts are off while EEPROM is written
                elif len(self.rx) >= self.options.rx_buffer:
                    self.rx_overflow += 1  # the firmware drops the byte silently
                else:
                    self.rx.append(byte)
                    if byte in (0x0A, 0x0D):
                        notify = True
            self.max_rx = max(self.max_rx, len(self.rx))
            if notify:
                self._cond.notify_all()

    def _realtime(self, byte: int) -> None:
        """Handle a real-time byte (called with the lock held)."""
        if byte == 0x18:
            self.reset_times.append(time.monotonic())
            self._reset_was_moving = self._moving()
            self._reset_pending = True
            self._cond.notify_all()
        elif byte == 0x3F:
            self._reply(self._status_report())
        elif byte == 0x21:
            if self._holds_to_drop > 0:
                self._holds_to_drop -= 1  # lost on the way: the firmware never sees it
                return
            self.hold_times.append(time.monotonic())
            if not self.hold and not self.alarm and not self.check_mode:
                self.hold = True
                self.hold_complete = not self._motion_busy
                self._cond.notify_all()
        elif byte == 0x7E:
            if self.hold and self.hold_complete:  # a resume during deceleration is ignored
                self.hold = self.hold_complete = False
                self._cond.notify_all()
            elif self.stalled:
                self.stalled = False
                self._cond.notify_all()
        elif 0x90 <= byte <= 0x94:
            self.feed_ov = {0x90: 100, 0x91: self.feed_ov + 10, 0x92: self.feed_ov - 10,
                            0x93: self.feed_ov + 1, 0x94: self.feed_ov - 1}[byte]
            self.feed_ov = min(200, max(10, self.feed_ov))
        elif 0x95 <= byte <= 0x97:
            self.rapid_ov = {0x95: 100, 0x96: 50, 0x97: 25}[byte]
        elif 0x99 <= byte <= 0x9D:
            self.spindle_ov = {0x99: 100, 0x9A: self.spindle_ov + 10, 0x9B: self.spindle_ov - 10,
                               0x9C: self.spindle_ov + 1, 0x9D: self.spindle_ov - 1}[byte]
            self.spindle_ov = min(200, max(10, self.spindle_ov))
        elif byte == 0xA0:
            self.coolant = self.coolant ^ {"M8"}

    def _moving(self) -> bool:
        return self._motion_busy and not (self.hold and self.hold_complete)

    def _status_report(self) -> str:
        pos = self._current_position()
        mask = int(self.settings[10])
        wco = np.array(self.interp.state.coord_systems[self.interp.state.coord_index]) + np.array(
            self.interp.state.g92)
        fields = [self.state]
        if mask & 1:
            fields.append("MPos:" + ",".join(f"{v:.3f}" for v in pos))
        else:
            fields.append("WPos:" + ",".join(f"{v:.3f}" for v in pos - wco))
        if mask & 2:
            fields.append(f"Bf:{self.options.planner_blocks - len(self.planner)},"
                          f"{self.options.rx_buffer - len(self.rx)}")
        feed = 0.0
        if self._current is not None and self._motion_busy:
            planned, profile, t0 = self._current
            feed = profile.speed_at((time.monotonic() - t0) * self.scale) * 60.0
        spindle = self.spindle_s * self.spindle_ov / 100.0 if self.spindle_mode != "M5" else 0.0
        fields.append(f"FS:{feed:.0f},{spindle:.0f}")
        self._status_count += 1
        if self._status_count % 10 == 1:
            fields.append(f"WCO:{wco[0]:.3f},{wco[1]:.3f},{wco[2]:.3f}")
        else:
            fields.append(f"Ov:{self.feed_ov},{self.rapid_ov},{self.spindle_ov}")
        accessories = ("S" if self.spindle_mode == "M3" else "C" if self.spindle_mode == "M4" else "") + (
            "F" if "M8" in self.coolant else "") + ("M" if "M7" in self.coolant else "")
        if accessories:
            fields.append(f"A:{accessories}")
        return "<" + "|".join(fields) + ">"

    def _current_position(self) -> np.ndarray:
        if self._current is not None and self._motion_busy:
            planned, profile, t0 = self._current
            if self.hold and self.hold_complete:
                return self.position.copy()
            d = profile.distance_at((time.monotonic() - t0) * self.scale)
            return planned.start + np.array(planned.block.unit) * d
        return self.position.copy()

    # ------------------------------------------------------------------ protocol thread

    def _protocol_loop(self) -> None:
        self._boot_messages()
        busy_until = 0.0
        while not self._stopping:
            try:
                raw = self._next_line()
                if raw is None:
                    return
                busy_until = max(busy_until, time.monotonic()) + self.options.parse_time / self.scale
                delay = busy_until - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                self._handle_line(raw)
            except _Reset:
                while True:  # a second reset may arrive while handling the first
                    try:
                        self._do_reset()
                        break
                    except _Reset:
                        continue
            except OSError:
                return

    def _boot_messages(self) -> None:
        self._send(f"\r\nGrbl {VERSION} ['$' for help]\r\n")
        if self.alarm:
            self._reply("[MSG:'$H'|'$X' to unlock]")

    def _check_reset(self) -> None:
        if self._reset_pending:
            raise _Reset()

    def _wait(self, predicate, timeout: float | None = None) -> bool:
        """Wait (lock held) until predicate() or a reset; raise _Reset on reset."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not predicate():
            self._check_reset()
            if self._stopping:
                raise OSError("emulator stopped")
            left = 0.05 if deadline is None else min(0.05, deadline - time.monotonic())
            if left <= 0:
                return False
            self._cond.wait(left)
        self._check_reset()
        return True

    def _next_line(self) -> bytes | None:
        with self._cond:
            while True:
                self._check_reset()
                if self._stopping:
                    return None
                if not self.critical:
                    for index, byte in enumerate(self.rx):
                        if byte in (0x0A, 0x0D):
                            line = bytes(self.rx[:index])
                            del self.rx[:index + 1]
                            return line
                self._cond.wait(0.05)

    def _handle_line(self, raw: bytes) -> None:
        text = clean_line(raw.decode("latin-1"))
        if len(text) > MAX_LINE_CHARS:
            self._reply("error:11")
            return
        if not text:
            self._reply("ok")  # an empty line still gets an answer: why "\r\n" yields two
            return
        if text.startswith("$"):
            self.commands.append(text)
            self._system_command(text)
            return
        if self.alarm:
            self._reply("error:9")
            return
        self.program_lines += 1
        number = self.program_lines
        faults = self.options.faults
        if faults.error_at == number:
            self._reply("error:20")
            return
        if faults.alarm_at == number:
            self._hard_limit()
            return
        try:
            actions = self.interp.execute(text)
        except GcodeError as error:
            self._reply(f"error:{error.code}")
            return
        if not self._run_actions(actions, number):
            return
        with self._cond:
            self.executed.append(text)
            self._cond.notify_all()
        if faults.drop_ok_at != number:
            self._reply("ok")
        if faults.garbage_at == number:
            self._send(b"\xfe\xff\x13o\x8bk\x00 \xe5rr\r\n")
        if faults.stall_at == number:
            with self._cond:
                self._stall_pending = True
        if faults.disconnect_at == number:
            self._unplug()

    def _run_actions(self, actions: list[tuple], number: int) -> bool:
        """Execute interpreter actions; False if the line ended in an alarm."""
        with self._cond:
            for action in actions:
                kind = action[0]
                if kind == "move":
                    if self.check_mode:
                        continue
                    self._queue_move(action, number)
                elif kind == "sync":
                    if not self.check_mode:
                        self._ref_rest = True
                        self._wait(lambda: not self.planner and not self._motion_busy)
                elif kind == "eeprom":
                    self._eeprom_write()
                elif kind == "dwell":
                    if not self.check_mode:
                        self._ref_dwell += float(action[1])
                        self._ref_rest = True
                        deadline = time.monotonic() + action[1] / self.scale
                        self._wait(lambda: time.monotonic() >= deadline)
                elif kind == "spindle":
                    if not self.check_mode:
                        self.spindle_mode, self.spindle_s = action[1], action[2]
                        self.spindle_history.append((action[1], action[2]))
                elif kind == "coolant":
                    if not self.check_mode:
                        self.coolant = action[1]
                elif kind == "pause":
                    if not self.check_mode:
                        self.hold, self.hold_complete = True, True
                elif kind == "alarm":
                    if action[1] == 5:
                        self._probe_fail()
                    else:
                        self._soft_limit()
                    return False
        return True

    def _queue_move(self, action: tuple, number: int) -> None:
        _, target, feed, rapid, mode, s = action
        start = self._planned_end()
        from_rest = not self.planner and not self._motion_busy
        block = self._builder.make(start, target, feed_mm_min=feed, rapid=rapid, from_rest=from_rest)
        self._ref_moves.append((tuple(start), tuple(target), np.nan if feed is None else feed, rapid, self._ref_rest))
        self._ref_rest = False
        if block is None:
            return
        self._adding = True
        try:
            self._wait(lambda: len(self.planner) < self.options.planner_blocks)
        finally:
            self._adding = False
        self.planner.append(_Planned(block, np.array(start, dtype=float), np.array(target, dtype=float),
                                     number, mode, s))
        self._cond.notify_all()

    def _planned_end(self) -> np.ndarray:
        if self.planner:
            return self.planner[-1].target
        if self._current is not None and self._motion_busy:
            return self._current[0].target
        return self.position

    def _hard_limit(self) -> None:
        """A limit switch tripped: stop dead, beam off, ALARM:1, wait for a reset."""
        with self._cond:
            self.position = self._current_position()
            self.planner.clear()
            self._current = None
            self.spindle_mode, self.spindle_s = "M5", 0.0
            self.spindle_history.append(("M5", 0.0))
            self.alarm = self.critical = True
            self.alarms.append(1)
            self._cond.notify_all()
        self._reply("ALARM:1")
        self._reply("[MSG:Reset to continue]")

    def _soft_limit(self) -> None:
        """Soft limit (lock held): feed hold to a stop, then ALARM:2; position is kept."""
        if self._motion_busy or self.planner:
            self.hold, self.hold_complete = True, False
            self._cond.notify_all()
            self._wait(lambda: self.hold_complete or not self._motion_busy)
        self.planner.clear()
        self.spindle_mode, self.spindle_s = "M5", 0.0
        self.spindle_history.append(("M5", 0.0))
        self.alarm = self.critical = True
        self.alarms.append(2)
        self._cond.notify_all()
        self._reply("ALARM:2")
        self._reply("[MSG:Reset to continue]")

    def _probe_fail(self) -> None:
        """G38.2/G38.4 reached its target without touching anything (no probe here): ALARM:5."""
        if not self.check_mode:
            self._wait(lambda: not self.planner and not self._motion_busy)
        self.spindle_mode, self.spindle_s = "M5", 0.0
        self.spindle_history.append(("M5", 0.0))
        self.alarm = True
        self.alarms.append(5)
        self._cond.notify_all()
        self._reply("ALARM:5")

    def _unplug(self) -> None:
        """The USB cable is pulled: the board loses power (beam off) and the port vanishes."""
        with self._cond:
            self.planner.clear()
            self.spindle_mode, self.spindle_s = "M5", 0.0
            self.spindle_history.append(("M5", 0.0))
            self.disconnected = True
            self._stopping = True
            self._cond.notify_all()
        with self._write_lock:
            self._close_fds()

    def _do_reset(self) -> None:
        with self._cond:
            was_moving = self._reset_was_moving
            # The motion thread drops its block as soon as it sees the pending reset.
            deadline = time.monotonic() + 1.0
            while self._motion_busy and time.monotonic() < deadline:
                self._cond.wait(0.01)
            self.planner.clear()
            self.rx.clear()
            alarm = self.alarm or was_moving
            self.resets += 1
            self._reset_state()
            self.alarm = alarm
            self.spindle_history.append(("M5", 0.0))
            if was_moving:
                self.alarms.append(3)
            self._cond.notify_all()
        if was_moving:
            self._reply("ALARM:3")
        self._boot_messages()

    # ------------------------------------------------------------------ $ commands

    def _system_command(self, text: str) -> None:
        busy = self.state.startswith(("Run", "Hold"))
        if text == "$":
            self._reply("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]")
        elif text == "$$":
            if busy:
                return self._reply("error:8")
            for number in sorted(self.settings):
                value = self.settings[number]
                shown = f"{int(value)}" if number in INTEGER_SETTINGS else f"{value:.3f}"
                self._reply(f"${number}={shown}")
        elif text == "$I":
            self._reply(f"[VER:{VERSION}.{BUILD_DATE}:]")
            self._reply(f"[OPT:V,{self.options.planner_blocks},{self.options.rx_buffer}]")
        elif text == "$G":
            self._reply(f"[GC:{self.interp.state.modal_report()}]")
        elif text == "$#":
            st = self.interp.state
            for i, system in enumerate(st.coord_systems):
                self._reply(f"[G{54 + i}:" + ",".join(f"{v:.3f}" for v in system) + "]")
            self._reply("[G28:" + ",".join(f"{v:.3f}" for v in st.g28) + "]")
            self._reply("[G30:" + ",".join(f"{v:.3f}" for v in st.g30) + "]")
            self._reply("[G92:" + ",".join(f"{v:.3f}" for v in st.g92) + "]")
            self._reply("[TLO:0.000]")
            self._reply("[PRB:0.000,0.000,0.000:0]")
        elif text == "$N":
            self._reply("$N0=")
            self._reply("$N1=")
        elif text == "$C":
            if busy:
                return self._reply("error:8")
            if self.check_mode:
                self._reply("[MSG:Disabled]")
                self._reply("ok")
                with self._cond:  # leaving check mode soft-resets the machine
                    self._reset_pending = True
                    self._reset_was_moving = False
                raise _Reset()
            self.check_mode = True
            self._reply("[MSG:Enabled]")
        elif text == "$X":
            if self.alarm:
                self.alarm = False
                self._reply("[MSG:Caution: Unlocked]")
        elif text == "$H":
            if not self.settings[22]:
                return self._reply("error:5")
            with self._cond:
                self._homing = True
                self._wait(lambda: False, timeout=0.5 / self.scale)
                self.position = np.zeros(3)
                self._homing = False
                self.alarm = False
        elif text.startswith("$N") and "=" in text:
            self._eeprom_write()
        elif text.startswith("$") and "=" in text:
            return self._set_setting(text)
        elif text.startswith("$J="):
            return self._reply("error:20")  # jogging is not emulated
        else:
            return self._reply("error:3")
        self._reply("ok")

    def _set_setting(self, text: str) -> None:
        key, _, value = text[1:].partition("=")
        try:
            number, number_value = int(key), float(value)
        except ValueError:
            return self._reply("error:3" if not key.isdigit() else "error:2")
        if number not in self.settings:
            return self._reply("error:3")
        if number_value < 0:
            return self._reply("error:4")
        if number == 20 and number_value and not self.settings[22]:
            return self._reply("error:10")
        if self.state.startswith(("Run", "Hold")):
            return self._reply("error:8")
        self.settings[number] = number_value
        self._eeprom_write()
        with self._cond:
            self.kin = Kinematics.from_settings(self.settings, planner_blocks=self.options.planner_blocks)
            self.config = MachineConfig(laser_mode=bool(self.settings[32]), soft_limits=bool(self.settings[20]),
                                        max_travel=(self.settings[130], self.settings[131], self.settings[132]),
                                        arc_tolerance=self.settings[12])
            self.interp.config = self.config
            self._builder = BlockBuilder(self.kin)
        self._reply("ok")

    def _eeprom_write(self) -> None:
        """Write EEPROM like the AVR: the line's answer waits, and serial input is lost meanwhile."""
        until = time.monotonic() + self.options.eeprom_write_time / self.scale
        with self._cond:
            self._eeprom_until = until
            self._wait(lambda: time.monotonic() >= until)

    # ------------------------------------------------------------------ motion thread

    def _motion_loop(self) -> None:
        v = 0.0
        clock: float | None = None
        while True:
            with self._cond:
                while not self._stopping and (self._reset_pending or not self.planner or self.hold
                                              or self.stalled or self.critical):
                    if self._stall_pending and not self.stalled:
                        self.stalled, self._stall_pending = True, False
                    v, clock = 0.0, None
                    self._cond.wait(0.05)
                if self._stopping:
                    return
                if self._stall_pending:
                    self.stalled, self._stall_pending = True, False
                    v, clock = 0.0, None
                    continue
                if self._adding and len(self.planner) < self.options.planner_blocks:
                    # The protocol thread holds a parsed block waiting for this free slot; on
                    # GRBL it would join the look-ahead while this block runs.
                    self._cond.wait_for(lambda: not self._adding or self._reset_pending, timeout=0.005)
                    if self._reset_pending or not self.planner or self.hold or self.stalled or self.critical:
                        continue  # things changed while the lock was released
                planned = self.planner[0]
                window = [p.block for p in self.planner]
                fo, ro = self.feed_ov / 100.0, self.rapid_ov / 100.0
                block = planned.block
                profile = trapezoid(v, exit_speed(window, feed_override=fo, rapid_override=ro),
                                    block.nominal(fo, ro), block.acceleration, block.length)
                now = time.monotonic()
                t0 = clock if (clock is not None and v > 0 and clock <= now) else now
                self._current = (planned, profile, t0)
                self._motion_busy = True
                if self._first_motion is None:
                    self._first_motion = t0
                if (planned.mode, planned.s) != (self.spindle_mode, self.spindle_s):
                    self.spindle_mode, self.spindle_s = planned.mode, planned.s
                    self.spindle_history.append((planned.mode, planned.s))
                end = t0 + profile.duration / self.scale
                known = len(self.planner)
                while not (self._stopping or self._reset_pending or self.hold or self.critical):
                    left = end - time.monotonic()
                    if left <= 0:
                        break
                    self._cond.wait(left)
                    if len(self.planner) > known and self.planner and self.planner[0] is planned:
                        # GRBL re-plans the running block when a new one arrives: its exit
                        # speed may rise now that the look-ahead reaches further.
                        known = len(self.planner)
                        profile, t0, end = self._replan_running(planned, profile, t0, end, v)
                if self._stopping:
                    return
                if self._reset_pending or self.critical:
                    self.position = self._current_position()
                    self._motion_busy = False
                    self._current = None
                    v, clock = 0.0, None
                    self._cond.notify_all()
                    continue
                if self.hold:
                    v, clock = 0.0, None
                    self._feed_hold(planned, profile, t0)
                    continue
                self.planner.popleft()
                self.position = planned.target.copy()
                self.blocks_done += 1
                self._last_motion = end
                self._motion_busy = False
                self._current = None
                v, clock = profile.v_exit, end
                self._cond.notify_all()

    def _replan_running(self, planned: _Planned, profile, t0: float, end: float, v_entry: float):
        """Raise the running block's exit speed if the grown look-ahead allows (lock held)."""
        fo, ro = self.feed_ov / 100.0, self.rapid_ov / 100.0
        new_exit = exit_speed([p.block for p in self.planner], feed_override=fo, rapid_override=ro)
        if new_exit <= profile.v_exit + 1e-9:
            return profile, t0, end
        now = time.monotonic()
        tau = (now - t0) * self.scale
        remaining = planned.block.length - profile.distance_at(tau)
        if tau >= profile.duration or remaining <= 1e-9:
            return profile, t0, end
        speed = profile.speed_at(tau)
        planned.start = planned.start + np.array(planned.block.unit) * profile.distance_at(tau)
        planned.block = dataclasses.replace(planned.block, length=remaining)
        block = planned.block
        profile = trapezoid(speed, new_exit, block.nominal(fo, ro), block.acceleration, remaining)
        self._current = (planned, profile, now)
        return profile, now, now + profile.duration / self.scale

    def _feed_hold(self, planned: _Planned, profile, t0: float) -> None:
        """Decelerate to a stop inside the current block (lock held), then wait in Hold:0."""
        tau = (time.monotonic() - t0) * self.scale
        speed, done = profile.speed_at(tau), profile.distance_at(tau)
        a, length = planned.block.acceleration, planned.block.length
        stop = min(speed * speed / (2 * a), max(0.0, length - done))
        stop_time = (speed - np.sqrt(max(speed * speed - 2 * a * stop, 0.0))) / a
        deadline = time.monotonic() + stop_time / self.scale
        while not (self._stopping or self._reset_pending) and time.monotonic() < deadline:
            self._cond.wait(max(0.0, deadline - time.monotonic()))
        travelled = done + stop
        self.position = planned.start + np.array(planned.block.unit) * travelled
        remaining = length - travelled
        if self.planner and self.planner[0] is planned:
            if remaining > 1e-6:
                planned.block = dataclasses.replace(planned.block, length=remaining, junction_sqr=0.0)
                planned.start = self.position.copy()
            else:
                self.planner.popleft()
                self.blocks_done += 1
        self._last_motion = time.monotonic()
        self._motion_busy = False
        self._current = None
        if self.hold:
            self.hold_complete = True
        self._cond.notify_all()
