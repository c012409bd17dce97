"""Stopping GRBL safely: pause, resume and overrides (real-time bytes), `halt` (feed
hold, again if no Hold within 0.5 s, soft reset within 1 s of the signal) and the
watchdog that acts on a machine gone quiet mid-job (a stall `~` recovers, a lost `ok`,
an unnoticed alarm or hold). A mixin of `GrblStreamer`."""

from __future__ import annotations

import time

from machines.grbl_protocol import (CYCLE_START, FEED_HOLD, FEED_OV_MINUS_1, FEED_OV_MINUS_10, FEED_OV_PLUS_1,
                                    FEED_OV_PLUS_10, FEED_OV_RESET, SOFT_RESET, SPINDLE_OV_MINUS_1,
                                    SPINDLE_OV_MINUS_10, SPINDLE_OV_PLUS_1, SPINDLE_OV_PLUS_10, SPINDLE_OV_RESET)
from machines.stream_types import HaltReport, StreamError
from onestroke.errors import MachineError


class StreamStops:
    """Real-time controls, the safe halt and the mid-job watchdog of `GrblStreamer`."""

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

    def _stop_error(self, message: str, *, last_line: int, failed: int | None = None, halt: bool = True,
                    cls: type[StreamError] = StreamError, since: float | None = None) -> StreamError:
        """Halt (unless halt=False) and build the error a stream ends with: the message, how
        the halt went, and the last acknowledged file line (`last_line`, 0: none)."""
        since = time.monotonic() if since is None else since
        report = self.halt(since) if halt else None
        self._polling = False
        suffix = report.describe() if report is not None else ""
        where = f"last acknowledged line {last_line}" if last_line else "no line was acknowledged"
        text = "; ".join(part for part in (message, suffix, where) if part)
        return cls(text, last_acked_line=last_line, failed_line=failed, halt=report)

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
