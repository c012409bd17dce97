"""Job time from a model of GRBL 1.1's motion planner (what the machine will really take).

The rules, from GRBL's planner.c / motion_control.c and docs/laser.md:
- G2/G3 become chords: n = floor(|sweep| r / 2 / sqrt(e (2r - e))) with e = `$12`.
- Positions are whole steps (`$100/$101`); moves of zero steps are dropped.
- Per block: nominal speed = min(F, rapid rate), rapid rate and acceleration limited per
  axis: min over axes of limit_i / |u_i| for the unit direction u.
- Corner speed (junction deviation `$11` = d): v² = a_j d sin(θ/2) / (1 - sin(θ/2)),
  θ the angle between the moves, a_j the acceleration along u_out - u_in; capped by both
  blocks' nominal speeds. A reversal stops; a straight junction does not limit.
- Look-ahead: a block runs while the planner holds it and the next 14 (`planner_blocks`
  in all), the last of which must be able to stop. So block j may leave at most at the
  speed from which blocks j+1..j+14 can still brake to zero; it enters at the speed block
  j-1 left with. Forced stops (M3/M4/M5, M7/M8/M9 changes, G4, S changes off motion)
  drain the planner.
- Trapezoid per block: accelerate at a, cruise, decelerate at a.
Assumes the sender keeps the planner full (true for character-counting streaming at
115200 baud unless segments are shorter than ~0.05 mm at high feed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.laser.gcode_read import GcodeMoves, parse_gcode
from machines.laser_profile import LaserProfile

_ARC_EPSILON = 5e-7  # GRBL's ARC_ANGULAR_TRAVEL_EPSILON
_STRAIGHT = 1e30     # GRBL's SOME_LARGE_VALUE for straight junctions


@dataclass(frozen=True)
class JobTime:
    """Seconds the job takes on GRBL, with the break-down.

    total_seconds: whole program. line_seconds (n_lines,): cumulative seconds at the end
    of each line (for an ETA while streaming). burn_seconds / travel_seconds: motion with
    the beam able to fire (M3/M4, S > 0, not G0) and all other motion. burn_length / travel_length: mm. naive_seconds: the length / feed
    figure common senders show (G1 at F, G0 at the profile's rapid rate). blocks: planner
    blocks after arc splitting.
    """

    total_seconds: float
    line_seconds: np.ndarray
    burn_seconds: float
    travel_seconds: float
    burn_length: float
    travel_length: float
    naive_seconds: float
    blocks: int


def _axis_limit(limits: np.ndarray, unit: np.ndarray) -> np.ndarray:
    """GRBL's limit_value_by_axis_maximum: min over axes of limit_i / |u_i| -> (M,)."""
    with np.errstate(divide="ignore"):
        ratio = np.where(np.abs(unit) > 0, limits[None, :] / np.abs(unit), np.inf)
    return ratio.min(axis=1)


def _lround(values: np.ndarray) -> np.ndarray:
    """C's lround: nearest integer, halves away from zero (numpy's rint rounds to even)."""
    return np.sign(values) * np.floor(np.abs(values) + 0.5)


def expand_arcs(moves: GcodeMoves, arc_tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Split arcs into GRBL's chords (`mc_arc`); other moves pass through.

    Returns segments (B, 2, 2) as (start, end) pairs in mm and owner (B,): the index of
    the move each segment belongs to.
    """
    n = len(moves)
    is_arc = (moves.kind >= 2) & np.isfinite(moves.centre[:, 0])
    counts = np.ones(n, dtype=int)
    if is_arc.any():
        c = moves.centre[is_arc]
        r_vec = moves.start[is_arc] - c
        rt = moves.end[is_arc] - c
        radius = np.hypot(*r_vec.T)
        travel = np.arctan2(r_vec[:, 0] * rt[:, 1] - r_vec[:, 1] * rt[:, 0], (r_vec * rt).sum(axis=1))
        cw = moves.kind[is_arc] == 2
        travel = np.where(cw & (travel >= -_ARC_EPSILON), travel - 2 * np.pi, travel)
        travel = np.where(~cw & (travel <= _ARC_EPSILON), travel + 2 * np.pi, travel)
        e = arc_tolerance
        with np.errstate(invalid="ignore"):
            segs = np.floor(np.abs(0.5 * travel * radius) / np.sqrt(e * np.maximum(2 * radius - e, e)))
        counts[is_arc] = np.maximum(1, np.nan_to_num(segs).astype(int))
    owner = np.repeat(np.arange(n), counts)
    first = np.cumsum(counts) - counts
    step = np.arange(len(owner)) - first[owner]  # 0..count-1 within the move
    ends = moves.end[owner].copy()
    starts = moves.start[owner].copy()
    if is_arc.any():
        arc_index = np.full(n, -1)
        arc_index[is_arc] = np.arange(is_arc.sum())
        sel = is_arc[owner]
        k = arc_index[owner[sel]]
        cnt = counts[owner[sel]]
        theta0 = np.arctan2(r_vec[k, 1], r_vec[k, 0])
        centre = c[k]

        def on_circle(i):
            angle = theta0 + travel[k] * i / cnt
            return centre + radius[k, None] * np.c_[np.cos(angle), np.sin(angle)]

        s_i, e_i = step[sel], step[sel] + 1
        arc_starts = np.where((s_i == 0)[:, None], moves.start[owner[sel]], on_circle(s_i))
        arc_ends = np.where((e_i == cnt)[:, None], moves.end[owner[sel]], on_circle(e_i))
        starts[sel], ends[sel] = arc_starts, arc_ends
    return np.stack([starts, ends], axis=1), owner


def block_times(start: np.ndarray, end: np.ndarray, feed: np.ndarray, rapid: np.ndarray,
                stop_before: np.ndarray, profile: LaserProfile) -> np.ndarray:
    """Seconds of each straight move under GRBL's planner model.

    start, end (B, 2) mm; feed (B,) mm/min; rapid (B,) G0; stop_before (B,) forced stop
    before the move. Returns (B,) seconds (0 for moves of zero steps).
    """
    steps = np.array([profile.steps_per_mm_x, profile.steps_per_mm_y])
    # GRBL plans between whole step positions (lround: halves away from zero); this is
    # what makes tiny segments uneven. Each block starts where the previous one ended.
    s1 = _lround(end * steps)
    s0 = np.vstack([_lround(start[:1] * steps), s1[:-1]])
    delta = (s1 - s0) / steps
    length_all = np.hypot(*delta.T) if len(delta) else np.zeros(0)
    keep = length_all > 0
    out = np.zeros(len(start))
    if not keep.any():
        return out
    # a stop before a dropped block still happens before the next kept one
    stop_cum = np.cumsum(stop_before)
    idx = np.flatnonzero(keep)
    prev_kept_stop = np.concatenate([[0], stop_cum[idx[:-1]]])
    stop = (stop_cum[idx] - prev_kept_stop) > 0
    stop[0] = True  # the planner starts empty
    length = length_all[keep]
    unit = delta[keep] / length[:, None]
    max_rates = np.array([profile.max_rate_x, profile.max_rate_y]) / 60.0
    accels = np.array([profile.acceleration_x, profile.acceleration_y])
    rapid_rate = _axis_limit(max_rates, unit)
    accel = _axis_limit(accels, unit)
    f = np.nan_to_num(feed[keep], nan=0.0) / 60.0
    nominal = np.where(rapid[keep], rapid_rate, np.minimum(np.maximum(f, 1.0 / 60.0), rapid_rate))

    # junction speeds
    prev_unit = np.vstack([unit[:1], unit[:-1]])
    cos_theta = -(prev_unit * unit).sum(axis=1)
    junction = unit - prev_unit
    jnorm = np.hypot(*junction.T)
    with np.errstate(invalid="ignore", divide="ignore"):
        junit = junction / jnorm[:, None]
        jaccel = _axis_limit(accels, np.nan_to_num(junit))
        sin_half = np.sqrt(np.clip(0.5 * (1.0 - cos_theta), 0.0, 1.0))
        vj2 = jaccel * profile.junction_deviation * sin_half / (1.0 - sin_half)
    vj2 = np.where(cos_theta > 0.999999, 0.0, np.where(cos_theta < -0.999999, _STRAIGHT, vj2))
    prev_nominal = np.concatenate([[0.0], nominal[:-1]])
    max_entry = np.minimum(vj2, np.minimum(nominal, prev_nominal) ** 2)
    max_entry[stop] = 0.0

    b = len(length)
    reach = 2.0 * accel * length  # v² gained or lost over a block
    window = profile.planner_blocks
    pad_entry = np.concatenate([max_entry, np.zeros(window)])
    pad_reach = np.concatenate([reach, np.zeros(window)])
    j = np.arange(b)
    # backward pass of every look-ahead window at once: block j+window-1 exits at 0
    limit = np.zeros(b)
    for d in range(window - 1, 0, -1):
        k = j + d
        limit = np.minimum(pad_entry[k], limit + pad_reach[k])
    # forward pass e_j = min(limit_j, e_{j-1} + reach_j), e_{-1} = 0, in closed form
    cum = np.cumsum(reach)
    exit_sq = np.maximum(cum + np.minimum(0.0, np.minimum.accumulate(limit - cum)), 0.0)
    exit_sq = np.minimum(exit_sq, limit)
    entry_sq = np.concatenate([[0.0], exit_sq[:-1]])
    entry_sq[stop] = 0.0
    # trapezoid (or triangle) per block
    peak_sq = np.minimum(nominal ** 2, (reach + entry_sq + exit_sq) / 2.0)
    peak_sq = np.maximum(peak_sq, np.maximum(entry_sq, exit_sq))
    v0, v1, vp = np.sqrt(entry_sq), np.sqrt(exit_sq), np.sqrt(peak_sq)
    ramp = (peak_sq - entry_sq) / (2 * accel) + (peak_sq - exit_sq) / (2 * accel)
    cruise = np.maximum(length - ramp, 0.0)
    out[keep] = (vp - v0) / accel + (vp - v1) / accel + cruise / vp
    return out


def estimate_moves_time(moves: GcodeMoves, profile: LaserProfile) -> JobTime:
    """`JobTime` of parsed moves (see `parse_gcode`)."""
    n_lines = moves.n_lines
    if len(moves) == 0:
        dwell = moves.line_dwell
        return JobTime(float(dwell.sum()), np.cumsum(dwell), 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    segments, owner = expand_arcs(moves, profile.arc_tolerance)
    stop = moves.stop_before[owner] & (np.r_[True, owner[1:] != owner[:-1]])
    rapid = moves.kind[owner] == 0
    seconds = block_times(segments[:, 0], segments[:, 1], moves.feed[owner], rapid, stop, profile)
    per_move = np.bincount(owner, weights=seconds, minlength=len(moves))
    per_line = np.bincount(moves.line, weights=per_move, minlength=n_lines) + moves.line_dwell
    chord = np.hypot(*(segments[:, 1] - segments[:, 0]).T)
    move_length = np.bincount(owner, weights=chord, minlength=len(moves))
    cutting = moves.kind != 0
    feed = np.nan_to_num(moves.feed, nan=profile.rapid_rate)
    naive = float((move_length[cutting] / np.maximum(feed[cutting], 1e-9)).sum() * 60.0
                  + move_length[~cutting].sum() / profile.rapid_rate * 60.0)
    burn = moves.laser_on  # G1 with the laser off (M5 or S0, e.g. framing) is travel
    return JobTime(
        total_seconds=float(per_line.sum()), line_seconds=np.cumsum(per_line),
        burn_seconds=float(per_move[burn].sum()), travel_seconds=float(per_move[~burn].sum()),
        burn_length=float(move_length[burn].sum()), travel_length=float(move_length[~burn].sum()),
        naive_seconds=naive, blocks=int((seconds > 0).sum()))


def estimate_gcode_time(lines, profile: LaserProfile) -> JobTime:
    """`JobTime` of a G-code program given as lines (str, with or without endings)."""
    return estimate_moves_time(parse_gcode(lines, laser_mode=profile.laser_mode), profile)


def format_duration(seconds: float) -> str:
    """'1:02:03', '2:05' or '12.3 s'."""
    if seconds < 60:
        return f"{seconds:.1f} s"
    whole = int(round(seconds))
    h, rest = divmod(whole, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"
