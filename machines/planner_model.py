"""GRBL's motion planner as a time model: per-axis limits, junction deviation, look-ahead.

Used by the emulator (to run moves in real time) and by senders for job-time estimates.
Rules follow GRBL 1.1 `planner.c`: each block's nominal speed and acceleration are limited
per axis ($110-$112 in mm/min, $120-$122 in mm/s^2); the corner speed comes from junction
deviation ($11): v^2 = a * delta * sin(theta/2) / (1 - sin(theta/2)); entry speeds come
from a backward pass over the blocks in the planner (15) that must end at rest, and each
block runs a trapezoid (accelerate, cruise, decelerate). Units: mm, mm/s, mm/s^2, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

SOME_LARGE_VALUE = 1.0e38
MINIMUM_FEED_RATE = 1.0 / 60.0  # mm/s, GRBL's MINIMUM_FEED_RATE of 1 mm/min


@dataclass(frozen=True, kw_only=True)
class Kinematics:
    """Machine limits for the planner model.

    max_rate: (3,) mm/min for X, Y, Z ($110-$112); acceleration: (3,) mm/s^2 ($120-$122);
    junction_deviation in mm ($11); arc_tolerance in mm ($12); planner_blocks is the
    look-ahead depth (15 on an Uno).
    """

    max_rate: tuple[float, float, float] = (6000.0, 6000.0, 500.0)
    acceleration: tuple[float, float, float] = (500.0, 500.0, 10.0)
    junction_deviation: float = 0.01
    arc_tolerance: float = 0.002
    planner_blocks: int = 15

    @classmethod
    def from_settings(cls, settings: dict[int, float], *, planner_blocks: int = 15) -> Kinematics:
        """Build from a `$$` dump ({number: value}); missing settings keep the defaults."""
        base = cls()
        rate = tuple(settings.get(110 + i, base.max_rate[i]) for i in range(3))
        acc = tuple(settings.get(120 + i, base.acceleration[i]) for i in range(3))
        return cls(max_rate=rate, acceleration=acc,
                   junction_deviation=settings.get(11, base.junction_deviation),
                   arc_tolerance=settings.get(12, base.arc_tolerance), planner_blocks=planner_blocks)


def limit_by_axis(limits: Sequence[float], unit: np.ndarray) -> float:
    """GRBL's limit_value_by_axis_maximum: the largest value along `unit` within per-axis limits."""
    best = SOME_LARGE_VALUE
    for limit, component in zip(limits, unit):
        if component != 0.0:
            best = min(best, abs(limit / component))
    return best


@dataclass(frozen=True)
class Block:
    """One planner block: a straight move.

    length mm; unit (3,) direction; rate mm/s as programmed (rapid moves: the rapid rate);
    rapid_rate mm/s along this direction; acceleration mm/s^2 along it; junction_sqr the
    squared corner-speed limit with the previous block ((mm/s)^2, 0 = start from rest).
    """

    length: float
    unit: tuple[float, float, float]
    rate: float
    rapid: bool
    rapid_rate: float
    acceleration: float
    junction_sqr: float

    def nominal(self, feed_override: float = 1.0, rapid_override: float = 1.0) -> float:
        """Nominal speed in mm/s after overrides (fractions, 1.0 = 100 %)."""
        speed = self.rate * (rapid_override if self.rapid else feed_override)
        return max(MINIMUM_FEED_RATE, min(speed, self.rapid_rate))


class BlockBuilder:
    """Turns successive targets into `Block`s, carrying the previous direction like GRBL."""

    def __init__(self, kinematics: Kinematics):
        self.kin = kinematics
        self.max_rate_s = tuple(r / 60.0 for r in kinematics.max_rate)
        self.previous_unit: np.ndarray | None = None

    def make(self, start: Sequence[float], target: Sequence[float], *, feed_mm_min: float | None,
             rapid: bool, from_rest: bool) -> Block | None:
        """Block from `start` to `target` (mm); None for a zero-length move (GRBL drops it).

        feed_mm_min is ignored for rapid moves; from_rest is True when the planner is empty.
        """
        delta = np.asarray(target, dtype=float) - np.asarray(start, dtype=float)
        length = float(math.sqrt(float(delta @ delta)))
        if length < 1e-9:
            return None
        unit = delta / length
        acceleration = limit_by_axis(self.kin.acceleration, unit)
        rapid_rate = limit_by_axis(self.max_rate_s, unit)
        rate = rapid_rate if rapid or feed_mm_min is None else feed_mm_min / 60.0
        junction_sqr = 0.0
        prev = self.previous_unit
        if not from_rest and prev is not None:
            cos_theta = -float(prev @ unit)
            if cos_theta > 0.999999:
                junction_sqr = 0.0  # full reversal: stop
            elif cos_theta < -0.999999:
                junction_sqr = SOME_LARGE_VALUE  # straight on
            else:
                junction_vec = unit - prev
                junction_vec /= float(np.linalg.norm(junction_vec))
                junction_acc = limit_by_axis(self.kin.acceleration, junction_vec)
                sin_half = math.sqrt(0.5 * (1.0 - cos_theta))
                junction_sqr = junction_acc * self.kin.junction_deviation * sin_half / (1.0 - sin_half)
        self.previous_unit = unit
        return Block(length, tuple(float(u) for u in unit), rate, rapid, rapid_rate, acceleration, junction_sqr)


@dataclass(frozen=True)
class Trapezoid:
    """Speed profile of one block: v0 -> peak (cruise) -> v_exit, in mm/s over `length` mm."""

    v0: float
    peak: float
    v_exit: float
    acceleration: float
    length: float
    t1: float  # end of the first ramp (s)
    t2: float  # end of the cruise (s)
    duration: float

    def distance_at(self, t: float) -> float:
        """Distance travelled (mm) after t seconds."""
        a, t = self.acceleration, min(max(t, 0.0), self.duration)
        sign1 = 1.0 if self.peak >= self.v0 else -1.0
        if t <= self.t1:
            return self.v0 * t + 0.5 * sign1 * a * t * t
        d1 = self.v0 * self.t1 + 0.5 * sign1 * a * self.t1 ** 2
        if t <= self.t2:
            return d1 + self.peak * (t - self.t1)
        tau = t - self.t2
        return min(self.length, d1 + self.peak * (self.t2 - self.t1) + self.peak * tau - 0.5 * a * tau * tau)

    def speed_at(self, t: float) -> float:
        """Speed (mm/s) after t seconds."""
        a = self.acceleration
        if t <= self.t1:
            return self.v0 + (a if self.peak >= self.v0 else -a) * t
        if t <= self.t2:
            return self.peak
        return max(0.0, self.peak - a * (t - self.t2))


def trapezoid(v0: float, v_exit: float, nominal: float, acceleration: float, length: float) -> Trapezoid:
    """The fastest profile over `length` that starts at v0 and ends at most at v_exit."""
    a = acceleration
    two_al = 2.0 * a * length
    v_exit = min(v_exit, math.sqrt(v0 * v0 + two_al))
    if v0 * v0 > v_exit * v_exit + two_al:  # cannot slow down in time (only after an override)
        v_exit = math.sqrt(v0 * v0 - two_al)
    peak = nominal
    d1 = abs(peak * peak - v0 * v0) / (2 * a)
    d3 = (peak * peak - v_exit * v_exit) / (2 * a) if peak > v_exit else 0.0
    if peak < v_exit:
        v_exit = peak
        d3 = 0.0
    if d1 + d3 > length:
        if v0 <= nominal:
            peak = math.sqrt(max((two_al + v0 * v0 + v_exit * v_exit) / 2.0, max(v0, v_exit) ** 2))
            peak = min(peak, max(nominal, v0))
        else:  # decelerating from above nominal all the way
            peak = v0
        d1 = abs(peak * peak - v0 * v0) / (2 * a)
        d3 = max(0.0, min(length - d1, (peak * peak - v_exit * v_exit) / (2 * a)))
    cruise = max(0.0, length - d1 - d3)
    t1 = abs(peak - v0) / a
    t2 = t1 + (cruise / peak if peak > 0 else 0.0)
    v_end = math.sqrt(max(0.0, peak * peak - 2 * a * d3))
    duration = t2 + (peak - v_end) / a
    return Trapezoid(v0, peak, v_end, a, length, t1, t2, duration)


def exit_speed(window: Sequence[Block], *, feed_override: float = 1.0, rapid_override: float = 1.0) -> float:
    """Exit speed (mm/s) allowed for window[0] by a backward pass that stops after window[-1]."""
    if len(window) < 2:
        return 0.0
    noms = [b.nominal(feed_override, rapid_override) for b in window]
    entry_sqr = 0.0  # speed at the end of the last block: the planner must be able to stop
    for k in range(len(window) - 1, 0, -1):
        block = window[k]
        max_entry = min(block.junction_sqr, noms[k] ** 2, noms[k - 1] ** 2)
        entry_sqr = min(max_entry, entry_sqr + 2.0 * block.acceleration * block.length)
    return math.sqrt(entry_sqr)


Barrier = None  # an item of a block sequence meaning "planner drains here" (sync)


def block_durations(items: Iterable[Block | float | None], *, window: int = 15) -> np.ndarray:
    """Seconds each item takes when the planner is never starved ("planner-limited" time).

    items: Blocks, None for a forced stop (planner sync), or a float for a dwell in seconds.
    Each block's exit speed is planned over itself and the next `window - 1` blocks (the
    planner holds `window` blocks including the executing one). Returns shape (len(items),).
    """
    items = list(items)
    out = np.zeros(len(items))
    v = 0.0
    for i, item in enumerate(items):
        if item is None:
            v = 0.0
            continue
        if not isinstance(item, Block):
            out[i] = float(item)
            v = 0.0
            continue
        look: list[Block] = [item]
        j = i + 1
        while j < len(items) and len(look) < window and isinstance(items[j], Block):
            look.append(items[j])
            j += 1
        v_entry = min(v, math.sqrt(item.junction_sqr) if item.junction_sqr < SOME_LARGE_VALUE else v)
        profile = trapezoid(v_entry, exit_speed(look), item.nominal(), item.acceleration, item.length)
        out[i] = profile.duration
        v = profile.v_exit
    return out
