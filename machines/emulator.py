"""A GRBL 1.1 emulator that speaks the serial protocol on a pseudo-terminal.

It models what matters to a sender: a 128-byte RX buffer fed at the wire rate that DROPS
overflow bytes like the firmware's serial interrupt; a parse time per line; a 15-block
planner whose motion takes the time GRBL's planner rules give (see `planner_model`);
real-time bytes (status, hold, resume, reset, overrides); check mode; the common errors
and alarms; and a log of every line it executed. `time_scale` > 1 runs everything (wire,
parsing, motion) that many times faster than a real machine.

Its time is a machine clock that does not depend on the host computer's speed or load
(`emulator_clock`): every byte from the host gets a machine arrival time (`emulator_host`),
parsing and motion advance the clock by their modelled times only, and wall time merely
paces the replies. `EmulatorStats` reports machine seconds.

The emulator is five mixins over one state: `emulator_transport` (pty, reader and writer
threads), `emulator_host` (the wire and the host's send times), `emulator_clock` (the
machine clock), `emulator_protocol` (real-time bytes, lines, `$` commands, status) and
`emulator_motion` (the planner core's incremental driver, holds, limits).

Use it in-process (`GrblEmulator(...).start_pty()` returns a device path for pyserial),
through pyserial as `sim://` (see `machines.sim_url`), or from a shell:
`onestroke emulator` prints a device path for any sender.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from machines.emulator_clock import EmulatorClock
from machines.emulator_host import EmulatorHost
from machines.emulator_motion import EmulatorMotion, Planned
from machines.emulator_protocol import BUILD_DATE, VERSION, EmulatorProtocol
from machines.emulator_transport import EmulatorTransport
from machines.gcode_interpreter import GcodeInterpreter, MachineConfig
from machines.grbl_settings import FIRMWARE_DEFAULTS, settings_from_profile
from machines.laser_profile import load_laser_profile
from machines.planner_model import BlockBuilder, Kinematics, plan_times
from onestroke.ranges import Range, check_ranges, ranged

# Speed-up over a real machine: 1000x already runs a 20-minute job in about a second.
TIME_SCALE = Range(0.0, 1000.0, name="--speed", low_open=True)

__all__ = ["BUILD_DATE", "DEFAULT_SETTINGS", "EmulatorOptions", "EmulatorStats", "Faults", "GrblEmulator", "VERSION"]


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

    time_scale: float = ranged(1.0, TIME_SCALE)
    baud: int = 115200
    usb_latency: float = 0.0005
    parse_time: float = 0.002
    eeprom_write_time: float = 0.017
    rx_buffer: int = 128
    planner_blocks: int = 15
    settings: Mapping[int, float] = field(default_factory=dict)
    boot_alarm: bool = False
    faults: Faults = Faults()

    def __post_init__(self) -> None:
        check_ranges(self)


@dataclass(frozen=True)
class EmulatorStats:
    """What the emulator measured. Times are machine seconds (the machine clock x
    time_scale; the same whatever the host computer's load, see `emulator_clock`).

    planner_limited_time: the motion time if the planner had never been starved (each
    block planned with the full look-ahead), from the blocks actually executed.
    motion_time: from the first block's start to the last block's end, as it ran.
    job_time: from the moment the host sent the first line after `mark_job_start` to the
    end of the last block or the arrival of the last `ok` at the host, whichever is
    later (0 if no job was marked). Includes holds (see `emulator_clock`).
    host_timeouts: how often the clock stopped waiting for a host that owed a line (one
    at the end of a stream is normal; more mean a host so slow it may have cost time).
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
    job_time: float = 0.0
    host_timeouts: int = 0


class GrblEmulator(EmulatorTransport, EmulatorHost, EmulatorClock, EmulatorProtocol, EmulatorMotion):
    """GRBL 1.1 on a file descriptor (the master side of a pty): transport, host, clock,
    protocol and motion mixins over one shared state, guarded by `_cond`."""

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
        self._init_clock()
        self._init_host()
        self._reset_state(power_up=True)

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
            self.planner: deque[Planned] = deque()
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
        self._status_count = 0
        self._homing = False

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
            job = 0.0
            if self._job_start is not None:
                job = float(max(self._last_motion or 0.0, self._last_ok) - self._job_start) * self.scale
            result = dict(job_time=job, host_timeouts=self.host_timeouts, lines_executed=len(self.executed), blocks_executed=self.blocks_done,
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
