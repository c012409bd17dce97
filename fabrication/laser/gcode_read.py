"""Reading GRBL G-code: a lenient parser into motion arrays, and a strict GRBL 1.1 validator.

`parse_gcode` understands what a laser job uses (G0-G3 with I/J or R, G4, G20/G21,
G90/G91, M3/M4/M5, M7/M8/M9, S, F; comments and line numbers) and ignores other words; the
preview and the time estimate read files through it. `validate_line` is strict: it accepts
only the words onestroke writes (G0/G1/G2/G3/G4/G20/G21/G90/G91/M3/M4/M5/M8/M9/S/F with
X/Y/I/J/P arguments) and checks GRBL's own rules (80 characters, one word per letter, a
defined feed before cutting moves, consistent arc centres).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

import numpy as np

from onestroke.errors import InputError
from onestroke.textfile import read_text

_COMMENT = re.compile(r"\([^)]*\)|;.*$")
_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
_GARBAGE = re.compile(r"[^A-Z0-9.+\-\s]")
INCH = 25.4


_SPACE = re.compile(r"\s+")


def strip_line(line: str) -> str:
    """What GRBL keeps of a line: upper case, without comments and spaces."""
    # the regexes only run when needed: most lines onestroke writes have neither
    if "(" in line or ";" in line:
        line = _COMMENT.sub("", line)
    if " " in line or "\t" in line or "\r" in line or "\n" in line:
        line = _SPACE.sub("", line)
    return line.upper()


@dataclass(frozen=True)
class GcodeMoves:
    """Every motion of a program, in mm, absolute machine coordinates.

    kind (M,) int8: 0 rapid G0, 1 G1, 2 G2 (clockwise), 3 G3. start, end, centre (M, 2)
    (centre NaN unless an arc). feed (M,) mm/min (NaN if never set). power (M,) S value.
    laser_on (M,) the beam can fire: spindle M3/M4 on, S > 0, not G0. line (M,) index of
    the source line. stop_before (M,) GRBL drains its planner to a full stop before this
    move (M3/M4/M5/M7/M8/M9 changes, G4, S changes outside laser motion). dwell_before (M,)
    seconds of G4 before it. end_dwell: seconds of G4 after the last move. n_lines: lines
    in the program. line_dwell: (n_lines,) seconds of G4 on each line.
    """

    kind: np.ndarray
    start: np.ndarray
    end: np.ndarray
    centre: np.ndarray
    feed: np.ndarray
    power: np.ndarray
    laser_on: np.ndarray
    line: np.ndarray
    stop_before: np.ndarray
    line_dwell: np.ndarray
    n_lines: int

    def __len__(self) -> int:
        return len(self.kind)


def parse_gcode(lines, *, laser_mode: bool = True) -> GcodeMoves:
    """Parse G-code lines (an iterable of str) into `GcodeMoves` (see class doc)."""
    kinds, starts, ends, centres, feeds, powers, ons, line_of, stops = [], [], [], [], [], [], [], [], []
    lines = list(lines)
    line_dwell = np.zeros(len(lines))
    x = y = 0.0
    motion = 0
    scale = 1.0
    relative = False
    feed = float("nan")
    s_value = 0.0
    spindle = 5  # 3, 4 or 5
    coolant = 9
    pending_stop = False
    for number, raw in enumerate(lines):
        text = strip_line(raw)
        if not text:
            continue
        words = _WORD.findall(text)
        g_codes = [float(v) for k, v in words if k == "G"]
        m_codes = [int(float(v)) for k, v in words if k == "M"]
        values = {k: float(v) for k, v in words if k not in "GM"}
        previous_motion, spindle_before = motion, spindle
        for g in g_codes:
            if g in (0, 1, 2, 3):
                motion = int(g)
            elif g == 20:
                scale = INCH
            elif g == 21:
                scale = 1.0
            elif g == 90:
                relative = False
            elif g == 91:
                relative = True
        if 4 in g_codes:
            line_dwell[number] = values.get("P", 0.0)
            pending_stop = True
        for m in m_codes:
            if m in (3, 4, 5) and m != spindle:
                spindle = m
                pending_stop = True
            elif m in (7, 8, 9) and m != coolant:
                coolant = m
                pending_stop = True
        if "F" in values:
            feed = values["F"] * scale
        has_axes = "X" in values or "Y" in values
        is_motion = has_axes and 4 not in g_codes and not any(g in (28, 30, 53, 92, 10) for g in g_codes)
        # GRBL gcode.c: in laser mode any line that moves (G0 too) carries its S through the
        # planner; a spindle-on S change on a line that does not move drains the planner, and
        # so does, under M3, a switch between G0 and G1/G2/G3 mode on a line that does not move
        force_sync = False
        if laser_mode and not is_motion and spindle_before == 3:
            cutting_before, cutting_now = previous_motion in (1, 2, 3), motion in (1, 2, 3)
            force_sync = cutting_before != cutting_now
        s_changed = "S" in values and values["S"] != s_value
        if (s_changed or force_sync) and spindle_before != 5 and not (laser_mode and is_motion):
            pending_stop = True
        if "S" in values:
            s_value = values["S"]
        if not is_motion:
            continue
        tx = values.get("X", 0.0 if relative else x / scale) * scale
        ty = values.get("Y", 0.0 if relative else y / scale) * scale
        if relative:
            tx, ty = x + tx, y + ty
        centre = (np.nan, np.nan)
        if motion in (2, 3):
            if "R" in values:
                centre = _centre_from_radius(x, y, tx, ty, values["R"] * scale, motion == 2)
            else:
                centre = (x + values.get("I", 0.0) * scale, y + values.get("J", 0.0) * scale)
        kinds.append(motion)
        starts.append((x, y))
        ends.append((tx, ty))
        centres.append(centre)
        feeds.append(feed)
        powers.append(s_value)
        ons.append(spindle in (3, 4) and s_value > 0 and motion != 0)
        line_of.append(number)
        stops.append(pending_stop)
        pending_stop = False
        x, y = tx, ty
    return GcodeMoves(
        kind=np.array(kinds, dtype=np.int8), start=np.array(starts, dtype=float).reshape(-1, 2),
        end=np.array(ends, dtype=float).reshape(-1, 2), centre=np.array(centres, dtype=float).reshape(-1, 2),
        feed=np.array(feeds, dtype=float), power=np.array(powers, dtype=float),
        laser_on=np.array(ons, dtype=bool), line=np.array(line_of, dtype=int),
        stop_before=np.array(stops, dtype=bool), line_dwell=line_dwell, n_lines=len(lines))


def _centre_from_radius(x0, y0, x1, y1, r, clockwise):
    # GRBL's radius-mode rule: negative R picks the longer arc
    dx, dy = x1 - x0, y1 - y0
    d2 = dx * dx + dy * dy
    h2 = r * r - d2 / 4
    if d2 == 0 or h2 < -1e-9:
        return (np.nan, np.nan)
    h = np.sqrt(max(h2, 0.0) / d2)
    if clockwise:
        h = -h
    if r < 0:
        h = -h
    return (x0 + dx / 2 - h * dy, y0 + dy / 2 + h * dx)


def read_gcode_file(path: str | os.PathLike) -> list[str]:
    """Lines of a G-code file (without endings); InputError if it cannot be read."""
    return read_text(path, what="G-code file", expect="a .gcode/.nc file").splitlines()


# -- strict validation -------------------------------------------------------------------

ALLOWED_G = {0, 1, 2, 3, 4, 20, 21, 90, 91}
ALLOWED_M = {3, 4, 5, 8, 9}
ALLOWED_LETTERS = set("GMSFXYIJP")
MAX_LINE = 80


class GcodeValidator:
    """Checks lines one by one against GRBL 1.1's rules and onestroke's word list.

    `check(line)` returns None or a one-line reason; it keeps the modal state (position,
    feed, units, distance mode) that the rules depend on.
    """

    def __init__(self, *, max_power: float = 1000.0) -> None:
        self.max_power = max_power
        self.x = self.y = 0.0
        self.feed_set = False
        self.motion = None
        self.scale = 1.0
        self.relative = False

    def check(self, line: str) -> str | None:
        if "\r" in line or "\n" in line:
            return "line contains a line-end character"
        if line != line.rstrip():
            return "trailing whitespace"
        text = strip_line(line)
        if len(text) > MAX_LINE:
            return f"{len(text)} characters after stripping (GRBL allows {MAX_LINE})"
        if not text:
            return None
        if _GARBAGE.search(text):
            return f"unexpected character in {text!r}"
        words = _WORD.findall(text)
        if "".join(k + v for k, v in words) != text:
            return f"malformed words in {text!r}"
        letters = [k for k, _ in words]
        bad = sorted(set(letters) - ALLOWED_LETTERS)
        if bad:
            return f"word(s) {''.join(bad)} not allowed"
        non_modal = [k for k in letters if k not in "GM"]
        if len(non_modal) != len(set(non_modal)):
            return "a word letter repeats (GRBL error 25)"
        g_codes, m_codes = [], []
        for k, v in words:
            if k in "GM":
                if "." in v or v.startswith(("+", "-")):
                    return f"{k}{v} is not a plain integer code"
                (g_codes if k == "G" else m_codes).append(int(v))
        if set(g_codes) - ALLOWED_G:
            return f"G{sorted(set(g_codes) - ALLOWED_G)[0]} not allowed"
        if set(m_codes) - ALLOWED_M:
            return f"M{sorted(set(m_codes) - ALLOWED_M)[0]} not allowed"
        motions = [g for g in g_codes if g in (0, 1, 2, 3)]
        if len(motions) > 1 or (motions and 4 in g_codes):
            return "two motion commands on one line (GRBL error 21)"
        if len(m_codes) > 1 and len({m in (3, 4, 5) for m in m_codes}) == 1:
            return "two M codes of one group on one line"
        values = {k: float(v) for k, v in words if k not in "GM"}
        for g in g_codes:
            if g == 20:
                self.scale = INCH
            elif g == 21:
                self.scale = 1.0
            elif g == 90:
                self.relative = False
            elif g == 91:
                self.relative = True
        if 4 in g_codes:
            if "P" not in values or values["P"] < 0:
                return "G4 needs a P value >= 0"
        elif "P" in values:
            return "P given without G4"
        if "S" in values and not 0 <= values["S"] <= self.max_power:
            return f"S{values['S']:g} outside 0..{self.max_power:g}"
        if "F" in values:
            if values["F"] <= 0:
                return f"F{values['F']:g} must be > 0"
            self.feed_set = True
        if motions:
            self.motion = motions[0]
        has_axes = "X" in values or "Y" in values
        if ("I" in values or "J" in values) and self.motion not in (2, 3):
            return "I/J given outside an arc"
        if not has_axes:
            if motions and motions[0] in (1, 2, 3):
                return "motion command without X or Y"
            return None
        if 4 in g_codes:
            return "axis words on a G4 line"
        if self.motion is None:
            return "axis words before any motion mode"
        tx = values.get("X", 0.0 if self.relative else self.x / self.scale) * self.scale
        ty = values.get("Y", 0.0 if self.relative else self.y / self.scale) * self.scale
        if self.relative:
            tx, ty = self.x + tx, self.y + ty
        if self.motion in (1, 2, 3) and not self.feed_set:
            return "cutting move before any F (GRBL error 22)"
        if self.motion in (2, 3):
            if "I" not in values and "J" not in values:
                return "arc without I or J"
            cx = self.x + values.get("I", 0.0) * self.scale
            cy = self.y + values.get("J", 0.0) * self.scale
            r0 = np.hypot(self.x - cx, self.y - cy)
            r1 = np.hypot(tx - cx, ty - cy)
            # GRBL's check (error 33): end radius within 0.005 mm, or 0.1 % of the radius
            if abs(r1 - r0) > 0.005 and (abs(r1 - r0) > 0.5 or abs(r1 - r0) > 0.001 * r0):
                return f"arc centre inconsistent: radius {r0:.4f} at start, {r1:.4f} at end"
            if r0 == 0:
                return "arc of zero radius"
        self.x, self.y = tx, ty
        return None


def validate_gcode(lines, *, max_power: float = 1000.0) -> list[tuple[int, str]]:
    """All problems of a program as (line index, reason); empty when it is valid."""
    validator = GcodeValidator(max_power=max_power)
    problems = []
    for number, line in enumerate(lines):
        reason = validator.check(line)
        if reason is not None:
            problems.append((number, reason))
    return problems
