"""What streaming to GRBL takes and gives: options, connection facts, progress, results
and the errors a stream ends with (`StreamError`, `StreamInterrupted`, with the halt's
`HaltReport`). Shared by the streamer's connection, stop and streaming parts."""

from __future__ import annotations

from dataclasses import dataclass, field

from onestroke.errors import InputError, MachineError

# The serial rates GRBL boards use (GRBL 1.1's default: 115200).
BAUD_RATES = (9600, 19200, 38400, 57600, 115200, 230400, 250000, 500000, 1000000)


def check_baud(rate, *, name: str = "--baud", shown: str | None = None) -> int:
    """`rate` if it is one of BAUD_RATES, else `InputError` naming `name`."""
    if isinstance(rate, bool) or rate not in BAUD_RATES:
        raise InputError(f"{name} {shown if shown is not None else rate} is not a serial rate GRBL uses; use one "
                         f"of {', '.join(map(str, BAUD_RATES))} (GRBL 1.1 default: 115200)")
    return int(rate)


def parse_baud(value, *, name: str = "--baud") -> int:
    """A baud rate as the user gave it (text such as "115200", or a whole number): read with
    the one number grammar (`onestroke.units.parse_integer`), then `check_baud`."""
    from onestroke.units import parse_integer

    return check_baud(parse_integer(value, what=name), name=name, shown=str(value).strip())


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


class Disconnected:
    """Put on the reply queue by the reader thread when the port fails."""

    def __init__(self, error: Exception):
        self.error = error
