"""An independent simulation of GRBL 1.1's planner and stepper, for checking the estimate.

Written from GRBL's documented rules (doc/markdown/settings.md, planner.c comments) by a
different method than machines/ (planner_model.py, job_time.py) and sharing no code with it: its own
G-code reader, GRBL's incremental arc generator (rotation with a correction every 12
segments), a literal 15-slot planner buffer re-planned block by block with GRBL's reverse
and forward passes, and a time-stepped execution of each block (speed raised or lowered
by a*dt each step, braking when the distance left demands it) instead of closed-form
trapezoids.
"""

from __future__ import annotations

import math
import re

_WORDS = re.compile(r"([A-Z])([-+]?[0-9]*\.?[0-9]+)")


class Block:
    __slots__ = ("length", "unit", "nominal", "accel", "max_entry", "entry", "rapid")


def _lround(value):
    # C's lround, as GRBL's planner uses: halves go away from zero
    return int(math.copysign(math.floor(abs(value) + 0.5), value))


def _limit(limits, unit):
    best = math.inf
    for lim, u in zip(limits, unit):
        if u != 0.0:
            best = min(best, lim / abs(u))
    return best


def simulate(lines, *, max_rate=(6000.0, 6000.0), accel=(500.0, 500.0), junction_deviation=0.01,
             arc_tolerance=0.002, steps_per_mm=(80.0, 80.0), planner_blocks=15, dt=1e-4) -> float:
    """Seconds GRBL takes for `lines` in laser mode, planner kept full. Rates mm/min, accel mm/s²."""
    rates = (max_rate[0] / 60.0, max_rate[1] / 60.0)
    program = _targets(lines, arc_tolerance)  # list of ("move", x, y, feed, rapid) | ("sync",)
    clock = 0.0
    pos_steps = (0, 0)
    prev_unit = None
    prev_nominal = 0.0
    buffer: list[Block] = []
    pending = iter(program)
    exhausted = False
    sync_waiting = False
    speed = 0.0

    def add(x, y, feed, rapid):
        nonlocal pos_steps, prev_unit, prev_nominal
        target = (_lround(x * steps_per_mm[0]), _lround(y * steps_per_mm[1]))
        dx = (target[0] - pos_steps[0]) / steps_per_mm[0]
        dy = (target[1] - pos_steps[1]) / steps_per_mm[1]
        if target == pos_steps:
            return  # GRBL drops blocks without steps
        pos_steps = target
        blk = Block()
        blk.length = math.hypot(dx, dy)
        blk.unit = (dx / blk.length, dy / blk.length)
        blk.rapid = rapid
        rapid_rate = _limit(rates, blk.unit)
        blk.nominal = rapid_rate if rapid else min(max(feed / 60.0, 1 / 60.0), rapid_rate)
        blk.accel = _limit(accel, blk.unit)
        if not buffer:
            junction_sq = 0.0
        else:
            cos_t = -(prev_unit[0] * blk.unit[0] + prev_unit[1] * blk.unit[1])
            if cos_t > 0.999999:
                junction_sq = 0.0
            elif cos_t < -0.999999:
                junction_sq = math.inf
            else:
                jx, jy = blk.unit[0] - prev_unit[0], blk.unit[1] - prev_unit[1]
                jn = math.hypot(jx, jy)
                ja = _limit(accel, (jx / jn, jy / jn))
                sin_half = math.sqrt(0.5 * (1.0 - cos_t))
                junction_sq = ja * junction_deviation * sin_half / (1.0 - sin_half)
        blk.max_entry = min(junction_sq, min(blk.nominal, prev_nominal) ** 2) if buffer else 0.0
        blk.entry = blk.max_entry
        prev_unit, prev_nominal = blk.unit, blk.nominal
        buffer.append(blk)
        replan()

    def replan():
        # GRBL planner_recalculate: reverse pass from the newest block (which must stop),
        # never touching the block being executed (index 0), then a forward pass.
        last = buffer[-1]
        if len(buffer) > 1:
            last.entry = min(last.max_entry, 2 * last.accel * last.length)
            for i in range(len(buffer) - 2, 0, -1):
                b = buffer[i]
                b.entry = min(b.max_entry, buffer[i + 1].entry + 2 * b.accel * b.length)
            for i in range(len(buffer) - 1):
                b, nxt = buffer[i], buffer[i + 1]
                if b.entry < nxt.entry:
                    nxt.entry = min(nxt.entry, b.entry + 2 * b.accel * b.length)

    def fill():
        nonlocal exhausted, sync_waiting, prev_nominal
        while len(buffer) < planner_blocks and not exhausted:
            if sync_waiting:
                if buffer:
                    return
                sync_waiting = False
            item = next(pending, None)
            if item is None:
                exhausted = True
                return
            if item[0] == "sync":
                sync_waiting = True
                continue
            add(*item[1:])

    fill()
    while buffer:
        blk = buffer[0]
        exit_sq = buffer[1].entry if len(buffer) > 1 else 0.0
        v_exit = math.sqrt(exit_sq)
        v = speed
        s = 0.0
        a, vmax, length = blk.accel, blk.nominal, blk.length
        while True:
            remaining = length - s
            v_brake = math.sqrt(exit_sq + 2 * a * remaining)
            if v_brake <= v + 1e-12:
                acc = -a
            elif v < vmax:
                acc = a
            else:
                acc = 0.0
            v_new = v + acc * dt
            if acc > 0:
                v_new = min(v_new, vmax, v_brake)
            elif acc < 0:
                v_new = max(v_new, v_exit, 0.0)
            step = 0.5 * (v + v_new) * dt
            if step >= remaining:
                # finish inside this step at a constant rate of change
                if v_new != v:
                    rate = (v_new - v) / dt
                    disc = v * v + 2 * rate * remaining
                    t_end = (-v + math.sqrt(max(disc, 0.0))) / rate if rate != 0 else remaining / v
                else:
                    t_end = remaining / v
                clock += t_end
                break
            s += step
            v = v_new
            clock += dt
        speed = v_exit
        buffer.pop(0)
        fill()
        if buffer and not (len(buffer) > 0 and buffer[0].entry > 0):
            speed = 0.0
    return clock


def _targets(lines, arc_tolerance):
    x = y = 0.0
    motion, feed, inches, relative = 0, 0.0, False, False
    spindle, coolant, s_val = 5, 9, 0.0
    out = []
    for raw in lines:
        text = re.sub(r"\(.*?\)|;.*", "", raw).replace(" ", "").upper()
        if not text:
            continue
        words = _WORDS.findall(text)
        vals = {}
        sync = False
        old_motion, old_spindle = motion, spindle
        for k, v in words:
            if k == "G":
                g = int(float(v))
                if g in (0, 1, 2, 3):
                    motion = g
                elif g == 4:
                    sync = True
                elif g == 20:
                    inches = True
                elif g == 21:
                    inches = False
                elif g == 90:
                    relative = False
                elif g == 91:
                    relative = True
            elif k == "M":
                m = int(float(v))
                if m in (3, 4, 5) and m != spindle:
                    spindle, sync = m, True
                if m in (7, 8, 9) and m != coolant:
                    coolant, sync = m, True
            else:
                vals[k] = float(v) * (25.4 if inches and k in "XYIJF" else 1.0)
        if "F" in vals:
            feed = vals["F"]
        moving = ("X" in vals or "Y" in vals)
        # laser mode ($32=1), gcode.c step 4: a line with axis words never syncs on S; one
        # without them syncs on an S change while the spindle is on, and under M3 also when
        # it switches between rapid and cutting motion modes
        forced = (not moving and old_spindle == 3
                  and (old_motion in (1, 2, 3)) != (motion in (1, 2, 3)))
        if old_spindle != 5 and not moving and (("S" in vals and vals["S"] != s_val) or forced):
            sync = True
        if "S" in vals:
            s_val = vals["S"]
        if sync:
            out.append(("sync",))
        if not moving:
            continue
        if relative:
            tx, ty = x + vals.get("X", 0.0), y + vals.get("Y", 0.0)
        else:
            tx, ty = vals.get("X", x), vals.get("Y", y)
        if motion in (2, 3):
            out.extend(_arc(x, y, tx, ty, vals.get("I", 0.0), vals.get("J", 0.0), motion == 2, feed, arc_tolerance))
        else:
            out.append(("move", tx, ty, feed, motion == 0))
        x, y = tx, ty
    return out


def _arc(x, y, tx, ty, i, j, clockwise, feed, tol):
    # GRBL motion_control.c mc_arc, transcribed rule by rule
    cx, cy = x + i, y + j
    r0, r1 = -i, -j
    rt0, rt1 = tx - cx, ty - cy
    travel = math.atan2(r0 * rt1 - r1 * rt0, r0 * rt0 + r1 * rt1)
    if clockwise:
        if travel >= -5e-7:
            travel -= 2 * math.pi
    elif travel <= 5e-7:
        travel += 2 * math.pi
    radius = math.hypot(i, j)
    segments = int(math.floor(abs(0.5 * travel * radius) / math.sqrt(tol * (2 * radius - tol))))
    out = []
    if segments:
        theta = travel / segments
        cos_t = 2.0 - theta * theta
        sin_t = theta * 0.16666667 * (cos_t + 4.0)
        cos_t *= 0.5
        count = 0
        for k in range(1, segments):
            if count < 12:
                r_new = r0 * sin_t + r1 * cos_t
                r0 = r0 * cos_t - r1 * sin_t
                r1 = r_new
                count += 1
            else:
                c, s = math.cos(k * theta), math.sin(k * theta)
                r0 = -i * c + j * s
                r1 = -i * s - j * c
                count = 0
            out.append(("move", cx + r0, cy + r1, feed, False))
    out.append(("move", tx, ty, feed, False))
    return out
