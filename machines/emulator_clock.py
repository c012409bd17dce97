"""The emulator's machine clock: discrete events in machine time, paced in wall time.

The machine's time does not depend on how fast the host computer is. Two threads take
part in it - the protocol thread (parser) and the motion thread - and each waits either
for a moment of machine time (a parse ends, a block ends, a dwell, an EEPROM write) or
for something to happen (a line, a free planner block). The clock thread advances the
clock only when both wait: to the earliest moment any of them, or a byte on the wire
(see `emulator_host`), waits for. Python's own time (handling a line, planning a block,
a busy host computer) therefore costs no machine time; only the modelled times do.

Wall time only paces the events so that a sender sees a machine running at `time_scale`
x real speed: an event at clock t happens at wall time `offset + t`, and `offset` only
grows (when the emulator or the host is late the clock stands still, it never rushes).

The host is the one input the clock cannot foresee. When the parser waits for a line and
the ideal host of `emulator_host` could already have sent one that would arrive before
the next event, the clock stands still and waits for the host in wall time, up to
a timeout (HOST_PATIENCE x the host's recent median, within HOST_TIMEOUT, at least
STREAMING_HOST_TIMEOUT for a host that pipelines); a host
that sends nothing for that long is "quiet" and the clock runs on without it until its
next line (a line sent later than that starts no earlier than the clock then: the only
way a slow host can cost machine time, at most what the planner still held, and it
needs a pause fifty times its usual one while it has lines to send).

What the clock counts while nothing is scheduled: in a feed hold or a stall it follows
wall time (scaled), so a hold of 2 s counts 2 s x time_scale of machine time, as on a
real machine; otherwise (an idle machine) it stands still. Hold, resume, reset and the
overrides act at the wall time they arrive at, as a person's actions do.
Clock values are in wall-equivalent seconds like every time in the emulator: machine
seconds are clock x time_scale. A mixin of `GrblEmulator`.
"""

from __future__ import annotations

import math
import statistics
import threading
import time
from collections import deque

PARTICIPANTS = 2  # the protocol and motion threads
# Wall seconds the clock waits for a host that owes a line: HOST_PATIENCE times the median
# of the host's recent answers (they grow when the host computer is busy), within bounds.
# A streaming (pipelining) host always has its next line ready mid-job: wait longer for it.
HOST_PATIENCE = 50.0
HOST_TIMEOUT = (0.1, 1.0)
STREAMING_HOST_TIMEOUT = 0.5  # the shortest wait for a pipelining host


class EmulatorClock:
    """Clock, participant waits and the clock thread of `GrblEmulator`."""

    def _init_clock(self) -> None:
        self._clock = 0.0  # machine clock (machine seconds / time_scale)
        self._offset = time.monotonic()  # wall time of clock 0 (only grows)
        self._clock_next: float | None = None  # the event the clock thread paces towards
        self._host_wait = False  # ... while it waits for the host
        self._following = False  # the clock follows wall time (hold, stall, quiet host)
        self._waiting: dict[int, float] = {}  # participant thread -> clock deadline (inf: none)
        self._changes = 0  # bumped by every state change that may wake a participant
        self._host_quiet = False
        self.host_timeouts = 0  # waits for the host that ran out (see EmulatorStats.host_timeouts)
        self._host_delays: deque[float] = deque([0.005], maxlen=64)  # wall seconds the host took
        self._parser_idle = False  # the protocol thread waits for a line from the host

    def _now(self) -> float:
        """The machine clock (machine seconds / time_scale)."""
        return self._clock

    def _wake_all(self) -> None:
        """A state change (lock held): every waiting participant re-checks what it waits for."""
        self._waiting.clear()
        self._changes += 1
        self._cond.notify_all()

    def _clock_wait(self, deadline: float | None = None) -> None:
        """Wait (lock held) until woken by a state change or the clock reaching `deadline`."""
        me = threading.get_ident()
        self._waiting[me] = math.inf if deadline is None else deadline
        self._cond.notify_all()  # the clock thread may advance now
        while me in self._waiting and not self._stopping:
            self._cond.wait(0.1)
        self._waiting.pop(me, None)

    def _sync_to_wall(self, kind: str) -> None:
        """(lock held) Move the clock towards the wall time a byte from the host arrived at:
        kind "line" only when the clock follows wall time; "query" (`?`) also while it
        paces towards an event; "control" (hold, resume, reset, overrides: a person's
        action in wall time) also while it waits for the host."""
        wall_clock = time.monotonic() - self._offset
        if self._clock_next is not None and (kind == "control" or (kind == "query" and not self._host_wait)):
            self._clock = max(self._clock, min(wall_clock, self._clock_next))
        elif self._following:
            self._clock = max(self._clock, wall_clock)

    def _advance(self, t: float) -> None:
        """(lock held) Set the clock to t, deliver the bytes on the wire by then, wake everyone."""
        self._clock = max(self._clock, t)
        self._deliver_due()
        self._wake_all()

    def _clock_loop(self) -> None:
        while True:
            with self._cond:
                if self._stopping:
                    return
                if len(self._waiting) < PARTICIPANTS:
                    self._cond.wait(0.05)  # a participant is busy: the clock stands still
                    continue
                changes, now = self._changes, self._clock
                events = [d for d in self._waiting.values() if d < math.inf]
                if self._wire:
                    events.append(self._wire[0][0])
                t_next = min(events) if events else math.inf
                if t_next <= now:
                    self._following = False
                    self._advance(now)
                    continue
                # (in a hold the machine runs on a person's time: no waiting for the host)
                if self._parser_idle and not (self._host_quiet or self.hold) and t_next > self._host_bound():
                    self._following = False
                    self._clock_next, self._host_wait = t_next, True
                    self._wait_for_host(changes)
                    self._clock_next, self._host_wait = None, False
                    continue
                if t_next == math.inf:
                    if self.hold or self.stalled:
                        self._follow_wall(changes)
                    else:  # idle: the clock stands still (a slow host costs nothing)
                        self._following = False
                        self._offset = max(self._offset, time.monotonic() - now)
                        self._cond.wait(0.05)
                    continue
                self._following = False
                self._offset = max(self._offset, time.monotonic() - now)
                target = self._offset + t_next
                self._clock_next = t_next
                while changes == self._changes and not self._stopping:
                    left = target - time.monotonic()
                    if left <= 0:
                        break
                    self._cond.wait(left)
                self._clock_next = None
                if changes == self._changes:
                    self._advance(t_next)

    def _wait_for_host(self, changes: int) -> None:
        """(lock held) The host could send a line now: wait for it, in wall time only."""
        start, lines = time.monotonic(), self._rx_cum
        low, high = HOST_TIMEOUT
        if self._host_pipelines:
            low = STREAMING_HOST_TIMEOUT
        deadline = start + min(high, max(low, HOST_PATIENCE * statistics.median(self._host_delays)))
        while changes == self._changes and not self._stopping:
            left = deadline - time.monotonic()
            if left <= 0:
                self._host_quiet = True
                self.host_timeouts += 1
                return
            self._cond.wait(left)
        if self._rx_cum != lines:
            self._host_delays.append(time.monotonic() - start)

    def _follow_wall(self, changes: int) -> None:
        """(lock held) Held or stalled with nothing scheduled: the clock runs with wall time."""
        if not self._following:
            self._offset = max(self._offset, time.monotonic() - self._clock)
            self._following = True
        self._cond.wait(0.02)
        if changes == self._changes:  # (a change re-plans first: the clock must not pass it)
            self._clock = max(self._clock, time.monotonic() - self._offset)
