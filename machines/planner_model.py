"""GRBL's motion planner as a time model: per-axis limits, junction deviation, look-ahead.

The one planner core of onestroke: the emulator runs it block by block (`BlockBuilder`,
`exit_speed`, `trapezoid`: the incremental driver) and job-time estimates run it over a
whole program at once (`plan_times`: the batch driver, the same rules vectorized).
Rules follow GRBL 1.1 `planner.c`: each block's nominal speed and acceleration are limited
per axis ($110-$112 in mm/min, $120-$122 in mm/s^2); the corner speed comes from junction
deviation ($11): v^2 = a * delta * sin(theta/2) / (1 - sin(theta/2)); entry speeds come
from a backward pass over the blocks in the planner (15) that must end at rest, and each
block runs a trapezoid (accelerate, cruise, decelerate). Units: mm, mm/s, mm/s^2, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

SOME_LARGE_VALUE = 1.0e38
MINIMUM_FEED_RATE = 1.0 / 60.0  # mm/s, GRBL's MINIMUM_FEED_RATE of 1 mm/min


@dataclass(frozen=True, kw_only=True)
class Kinematics:
    """Machine limits for the planner model.

    max_rate: (3,) mm/min for X, Y, Z ($110-$112); acceleration: (3,) mm/s^2 ($120-$122);
    junction_deviation in mm ($11); arc_tolerance in mm ($12); steps_per_mm: (3,)
    ($100-$102; GRBL plans between whole steps); planner_blocks is the look-ahead depth
    (15 on an Uno).
    """

    max_rate: tuple[float, float, float] = (6000.0, 6000.0, 500.0)
    acceleration: tuple[float, float, float] = (500.0, 500.0, 10.0)
    junction_deviation: float = 0.01
    arc_tolerance: float = 0.002
    steps_per_mm: tuple[float, float, float] = (80.0, 80.0, 250.0)
    planner_blocks: int = 15

    @classmethod
    def from_settings(cls, settings: dict[int, float], *, planner_blocks: int = 15) -> Kinematics:
        """Build from a `$$` dump ({number: value}); missing settings keep the defaults."""
        base = cls()
        rate = tuple(settings.get(110 + i, base.max_rate[i]) for i in range(3))
        acc = tuple(settings.get(120 + i, base.acceleration[i]) for i in range(3))
        steps = tuple(settings.get(100 + i, base.steps_per_mm[i]) for i in range(3))
        return cls(max_rate=rate, acceleration=acc, steps_per_mm=steps,
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
        self.steps = np.asarray(kinematics.steps_per_mm, dtype=float)
        self.previous_unit: np.ndarray | None = None

    def make(self, start: Sequence[float], target: Sequence[float], *, feed_mm_min: float | None,
             rapid: bool, from_rest: bool) -> Block | None:
        """Block from `start` to `target` (mm); None for a zero-length move (GRBL drops it).

        feed_mm_min is ignored for rapid moves; from_rest is True when the planner is empty.
        """
        # GRBL plans between whole step positions (lround), which makes tiny segments uneven
        steps = self.steps
        delta = (lround(np.asarray(target, dtype=float) * steps)
                 - lround(np.asarray(start, dtype=float) * steps)) / steps
        length = float(math.sqrt(float(delta @ delta)))
        if length == 0.0:
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


def lround(values: np.ndarray) -> np.ndarray:
    """C's lround: nearest integer, halves away from zero (numpy's rint rounds to even)."""
    return np.sign(values) * np.floor(np.abs(values) + 0.5)


def _axis_limit(limits: np.ndarray, unit: np.ndarray) -> np.ndarray:
    """`limit_by_axis` for many unit vectors (B, D) at once -> (B,)."""
    with np.errstate(divide="ignore"):
        ratio = np.where(np.abs(unit) > 0, limits[None, :] / np.abs(unit), np.inf)
    return ratio.min(axis=1)


@dataclass(frozen=True)
class BlockTable:
    """The planner blocks of a program as arrays, for the batch drivers.

    keep (M,) bool: the move makes a block (not zero steps); for the B kept ones, in
    order: length mm, accel mm/s^2, nominal mm/s, max_entry (mm/s)^2 (junction and
    nominal limits, 0 after a forced stop) and reach = 2 * accel * length ((mm/s)^2).
    """

    keep: np.ndarray
    length: np.ndarray
    accel: np.ndarray
    nominal: np.ndarray
    max_entry: np.ndarray
    reach: np.ndarray


def block_table(start: np.ndarray, end: np.ndarray, feed: np.ndarray, rapid: np.ndarray,
                stop_before: np.ndarray, kin: Kinematics) -> BlockTable:
    """GRBL's planner blocks (planner.c plan_buffer_line) for straight moves at once.

    start, end (M, D) mm with D <= 3 axes (X, Y[, Z]); feed (M,) mm/min (NaN: undefined);
    rapid (M,) G0; stop_before (M,) the planner drains before the move (forced stop).
    """
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    if not len(start):
        empty = np.zeros(0)
        return BlockTable(np.zeros(0, dtype=bool), empty, empty, empty, empty, empty)
    dims = start.shape[1] if start.ndim == 2 else 2
    steps = np.asarray(kin.steps_per_mm[:dims], dtype=float)
    s1 = lround(end * steps)
    s0 = np.vstack([lround(start[:1] * steps), s1[:-1]])  # each block starts where the last ended
    delta = (s1 - s0) / steps
    length_all = np.sqrt((delta * delta).sum(axis=1))
    keep = length_all > 0
    if not keep.any():
        empty = np.zeros(0)
        return BlockTable(keep, empty, empty, empty, empty, empty)
    # a stop before a dropped block still happens before the next kept one
    stop_cum = np.cumsum(stop_before)
    idx = np.flatnonzero(keep)
    prev_kept_stop = np.concatenate([[0], stop_cum[idx[:-1]]])
    stop = (stop_cum[idx] - prev_kept_stop) > 0
    stop[0] = True  # the planner starts empty
    length = length_all[keep]
    unit = delta[keep] / length[:, None]
    accels = np.asarray(kin.acceleration[:dims], dtype=float)
    rapid_rate = _axis_limit(np.asarray(kin.max_rate[:dims], dtype=float) / 60.0, unit)
    accel = _axis_limit(accels, unit)
    f = np.nan_to_num(np.asarray(feed, dtype=float)[keep], nan=0.0) / 60.0
    nominal = np.where(np.asarray(rapid)[keep], rapid_rate,
                       np.minimum(np.maximum(f, MINIMUM_FEED_RATE), rapid_rate))
    # junction speeds (planner.c plan_buffer_line)
    prev_unit = np.vstack([unit[:1], unit[:-1]])
    cos_theta = -(prev_unit * unit).sum(axis=1)
    junction = unit - prev_unit
    jnorm = np.sqrt((junction * junction).sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        jaccel = _axis_limit(accels, np.nan_to_num(junction / jnorm[:, None]))
        sin_half = np.sqrt(np.clip(0.5 * (1.0 - cos_theta), 0.0, 1.0))
        vj2 = jaccel * kin.junction_deviation * sin_half / (1.0 - sin_half)
    vj2 = np.where(cos_theta > 0.999999, 0.0, np.where(cos_theta < -0.999999, SOME_LARGE_VALUE, vj2))
    prev_nominal = np.concatenate([[0.0], nominal[:-1]])
    max_entry = np.minimum(vj2, np.minimum(nominal, prev_nominal) ** 2)
    max_entry[stop] = 0.0
    return BlockTable(keep, length, accel, nominal, max_entry, 2.0 * accel * length)


def window_limits(table: BlockTable, window: int) -> np.ndarray:
    """(B,) the squared exit speed each block may have with `window` blocks in the planner
    (itself and the next window - 1, the last of which must be able to stop): the backward
    pass of every look-ahead window at once."""
    b = len(table.length)
    pad_entry = np.concatenate([table.max_entry, np.zeros(window)])
    pad_reach = np.concatenate([table.reach, np.zeros(window)])
    j = np.arange(b)
    limit = np.zeros(b)
    for d in range(window - 1, 0, -1):
        k = j + d
        limit = np.minimum(pad_entry[k], limit + pad_reach[k])
    return limit


def plan_times(start: np.ndarray, end: np.ndarray, feed: np.ndarray, rapid: np.ndarray,
               stop_before: np.ndarray, kin: Kinematics, *, exits: bool = False):
    """Batch driver: seconds of each straight move when the planner is never starved.

    Arguments as `block_table`. Same rules as the incremental driver (`BlockBuilder`,
    `exit_speed`, `trapezoid`): each block may leave at most at the speed from which the
    next planner_blocks - 1 blocks can still brake to rest; it enters at the speed the
    previous one left with. Returns (M,) seconds (0 for moves of zero steps); with
    `exits`, also (M,) the squared speed leaving each move ((mm/s)^2, 0 for those).
    """
    table = block_table(start, end, feed, rapid, stop_before, kin)
    out = np.zeros(len(table.keep))
    leaving = np.zeros(len(table.keep))
    if not len(table.length):
        return (out, leaving) if exits else out
    length, accel, nominal, max_entry, reach = (table.length, table.accel, table.nominal, table.max_entry,
                                                table.reach)
    limit = window_limits(table, kin.planner_blocks)
    # forward pass e_j = min(limit_j, e_{j-1} + reach_j), e_{-1} = 0, in closed form
    cum = np.cumsum(reach)
    exit_sq = np.maximum(cum + np.minimum(0.0, np.minimum.accumulate(limit - cum)), 0.0)
    exit_sq = np.minimum(exit_sq, limit)
    entry_sq = np.concatenate([[0.0], exit_sq[:-1]])
    entry_sq[max_entry == 0.0] = 0.0
    # trapezoid (or triangle) per block
    peak_sq = np.minimum(nominal ** 2, (reach + entry_sq + exit_sq) / 2.0)
    peak_sq = np.maximum(peak_sq, np.maximum(entry_sq, exit_sq))
    v0, v1, vp = np.sqrt(entry_sq), np.sqrt(exit_sq), np.sqrt(peak_sq)
    ramp = (peak_sq - entry_sq) / (2 * accel) + (peak_sq - exit_sq) / (2 * accel)
    cruise = np.maximum(length - ramp, 0.0)
    out[table.keep] = (vp - v0) / accel + (vp - v1) / accel + cruise / vp
    leaving[table.keep] = exit_sq
    return (out, leaving) if exits else out
