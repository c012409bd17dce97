"""The emulator's motion: the incremental driver of the one planner core.

Blocks from `machines.planner_model.BlockBuilder` (step-quantized like the firmware) wait
in a 15-block planner; the running block follows `trapezoid(v_entry, exit_speed(planner))`
on the machine clock (`emulator_clock`), re-planned when a new block arrives, as GRBL re-plans; forced stops
drain the planner; feed hold decelerates inside the block; hard and soft limits and probe
failures raise their alarms with the beam off. The job-time estimate runs the same rules
over a whole program (`plan_times`). A mixin of `GrblEmulator`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from machines.planner_model import Block, exit_speed, trapezoid


@dataclass
class Planned:
    """A block in the planner with where it starts and ends (mm), its line and laser state."""

    block: Block
    start: np.ndarray
    target: np.ndarray
    line_index: int
    mode: str
    s: float


class EmulatorMotion:
    """Planner queue, motion thread, holds and limits of `GrblEmulator`."""

    def _moving(self) -> bool:
        return self._motion_busy and not (self.hold and self.hold_complete)

    def _current_position(self) -> np.ndarray:
        if self._current is not None and self._motion_busy:
            planned, profile, t0 = self._current
            if self.hold and self.hold_complete:
                return self.position.copy()
            d = profile.distance_at((self._now() - t0) * self.scale)
            return planned.start + np.array(planned.block.unit) * d
        return self.position.copy()

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
                        deadline = self._now() + action[1] / self.scale
                        self._wait(lambda: self._now() >= deadline, until=deadline)
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
        self.planner.append(Planned(block, np.array(start, dtype=float), np.array(target, dtype=float),
                                     number, mode, s))
        self._wake_all()

    def _planned_end(self) -> np.ndarray:
        if self.planner:
            return self.planner[-1].target
        if self._current is not None and self._motion_busy:
            return self._current[0].target
        return self.position

    def _alarm(self, code: int, *, critical: bool) -> None:
        """Beam off, planner emptied, ALARM:code (lock held); critical ones need a reset."""
        self.planner.clear()
        self.spindle_mode, self.spindle_s = "M5", 0.0
        self.spindle_history.append(("M5", 0.0))
        self.alarm = True
        self.critical = self.critical or critical
        self.alarms.append(code)
        self._wake_all()
        self._reply(f"ALARM:{code}")
        if critical:
            self._reply("[MSG:Reset to continue]")

    def _hard_limit(self) -> None:
        """A limit switch tripped: stop dead, beam off, ALARM:1, wait for a reset."""
        with self._cond:
            self.position = self._current_position()
            self._current = None
            self._alarm(1, critical=True)

    def _soft_limit(self) -> None:
        """Soft limit (lock held): feed hold to a stop, then ALARM:2; position is kept."""
        if self._motion_busy or self.planner:
            self.hold, self.hold_complete = True, False
            self._wake_all()
            self._wait(lambda: self.hold_complete or not self._motion_busy)
        self._alarm(2, critical=True)

    def _probe_fail(self) -> None:
        """G38.2/G38.4 reached its target without touching anything (no probe here): ALARM:5."""
        if not self.check_mode:
            self._wait(lambda: not self.planner and not self._motion_busy)
        self._alarm(5, critical=False)

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
                    self._clock_wait()
                if self._stopping:
                    return
                if self._stall_pending:
                    self.stalled, self._stall_pending = True, False
                    v, clock = 0.0, None
                    continue
                if self._adding and len(self.planner) < self.options.planner_blocks:
                    # The protocol thread holds a parsed block waiting for this free slot; on
                    # GRBL it would join the look-ahead while this block runs.
                    while (self._adding and len(self.planner) < self.options.planner_blocks
                           and not (self._reset_pending or self._stopping)):
                        self._clock_wait()  # (the clock stands still meanwhile)
                    if self._reset_pending or not self.planner or self.hold or self.stalled or self.critical:
                        continue  # things changed while the lock was released
                planned = self.planner[0]
                window = [p.block for p in self.planner]
                fo, ro = self.feed_ov / 100.0, self.rapid_ov / 100.0
                block = planned.block
                profile = trapezoid(v, exit_speed(window, feed_override=fo, rapid_override=ro),
                                    block.nominal(fo, ro), block.acceleration, block.length)
                now = self._now()
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
                    if self._now() >= end:
                        break
                    self._clock_wait(end)
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
                    self._wake_all()
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
                self._wake_all()

    def _replan_running(self, planned: Planned, profile, t0: float, end: float, v_entry: float):
        """Raise the running block's exit speed if the grown look-ahead allows (lock held)."""
        fo, ro = self.feed_ov / 100.0, self.rapid_ov / 100.0
        new_exit = exit_speed([p.block for p in self.planner], feed_override=fo, rapid_override=ro)
        if new_exit <= profile.v_exit + 1e-9:
            return profile, t0, end
        now = self._now()
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

    def _feed_hold(self, planned: Planned, profile, t0: float) -> None:
        """Decelerate to a stop inside the current block (lock held), then wait in Hold:0."""
        tau = (self._now() - t0) * self.scale
        speed, done = profile.speed_at(tau), profile.distance_at(tau)
        a, length = planned.block.acceleration, planned.block.length
        stop = min(speed * speed / (2 * a), max(0.0, length - done))
        stop_time = (speed - np.sqrt(max(speed * speed - 2 * a * stop, 0.0))) / a
        deadline = self._now() + stop_time / self.scale
        while not (self._stopping or self._reset_pending) and self._now() < deadline:
            self._clock_wait(deadline)
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
        self._last_motion = self._now()
        self._motion_busy = False
        self._current = None
        if self.hold:
            self.hold_complete = True
        self._wake_all()
