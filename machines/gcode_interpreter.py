"""GRBL 1.1h G-code semantics: one cleaned line in, the actions the firmware would take out.

The one G-code reader of onestroke: the emulator executes lines through it, and job
analysis (pre-check, bounding box, max S, time estimate, preview) reads files through it,
so both read G-code the same way. It follows gnea/grbl gcode.c: words (`gcode_words`),
then the error checks of step 3 in GRBL's order (a word no command uses is error:36),
then execution in GRBL's order of step 4. Positions are machine coordinates in mm,
shape (3,). Arcs come out as the chords GRBL cuts them into ($12, `arc_chords`).
"""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field

from machines.arc_chords import arc_chords
from machines.gcode_words import GcodeError, Words, read_words

__all__ = ["GcodeError", "GcodeInterpreter", "GcodeState", "MachineConfig", "Motion", "MM_PER_INCH"]

MM_PER_INCH = 25.4
MAX_LINE_NUMBER = 10_000_000

# Action tuples (kept as tuples: the emulator runs tens of thousands per job).
#   ("move", target(3,), feed_mm_min | None, rapid, spindle_mode, s)
#   ("sync",)                     planner drains before the next action
#   ("eeprom",)                   GRBL writes EEPROM now (serial input is lost meanwhile)
#   ("dwell", seconds)
#   ("spindle", mode, s)          mode in "M3", "M4", "M5"
#   ("coolant", frozenset of "M8")
#   ("pause",)                    M0: feed hold once the planner drains
#   ("end",)                      M2/M30: program end
#   ("alarm", code)               soft limit (ALARM:2), probe without contact (ALARM:5)


@dataclass
class GcodeState:
    """The parser's modal state (mutable; the interpreter copies it per line)."""

    position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    motion: float = 0  # 0, 1, 2, 3, 38.2-38.5, 80
    absolute: bool = True
    inches: bool = False
    plane: int = 17
    inverse_time: bool = False
    coord_index: int = 0  # G54 = 0 ... G59 = 5
    coord_systems: list[list[float]] = field(default_factory=lambda: [[0.0] * 3 for _ in range(6)])
    g92: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    g28: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    g30: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    tool_offset: float = 0.0
    spindle: str = "M5"
    s: float = 0.0
    feed: float = 0.0  # mm/min (or 1/min in G93); 0 = undefined
    coolant: frozenset = frozenset()
    tool: int = 0

    def modal_report(self) -> str:
        """The body of a `[GC:...]` reply."""
        coolant = " ".join(sorted(self.coolant)) or "M9"
        feed = self.feed / (MM_PER_INCH if self.inches else 1.0)
        return (f"G{self.motion:g} G{54 + self.coord_index} G{self.plane} G{20 if self.inches else 21} "
                f"G{90 if self.absolute else 91} G{93 if self.inverse_time else 94} {self.spindle} "
                f"{coolant} T{self.tool} F{feed:g} S{self.s:g}")


@dataclass(frozen=True, kw_only=True)
class MachineConfig:
    """What the interpreter needs from the settings: laser mode ($32), soft limits ($20),
    travel ($130-$132, mm) and arc tolerance ($12, mm)."""

    laser_mode: bool = True
    soft_limits: bool = False
    max_travel: tuple[float, float, float] = (400.0, 400.0, 0.0)
    arc_tolerance: float = 0.002


@dataclass(frozen=True)
class Motion:
    """The motion command of a line, before arcs are cut into chords: kind 0/1/2/3 (G0-G3)
    or 38 (probe); start, end (3,) mm; centre (3,) for arcs, else None."""

    kind: int
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    centre: tuple[float, float, float] | None


_CUTTING = (1, 2, 3)
_NUM = r"([-+]?(?:\d+\.?\d*|\.\d+))"
# the lines laser jobs are made of: [G0|G1] X.. Y.. [F..] [S..]; read without the general path
_SIMPLE = re.compile(rf"^(?:G0?([01]))?(?:X{_NUM})?(?:Y{_NUM})?(?:F{_NUM})?(?:S{_NUM})?$")


class GcodeInterpreter:
    """Executes cleaned lines against a `GcodeState`; raises `GcodeError` like GRBL would.

    After each `execute`, `motion` holds the line's `Motion` (None if it did not move).
    """

    def __init__(self, config: MachineConfig = MachineConfig(), state: GcodeState | None = None):
        self.config = config
        self.state = state or GcodeState()
        self.motion: Motion | None = None

    def reset_modal(self) -> None:
        """Soft reset: modal state back to defaults, position and stored offsets kept."""
        old = self.state
        self.state = GcodeState(position=list(old.position), coord_systems=old.coord_systems,
                                g28=old.g28, g30=old.g30)

    def execute(self, line: str) -> list[tuple]:
        """Interpret one cleaned, upper-case line; return its actions and commit the state."""
        self.motion = None
        if not line:
            return []
        fast = self._simple(line)
        if fast is not None:
            return fast
        words = read_words(line)
        st = copy.copy(self.state)
        st.position = list(st.position)
        plan = self._check(words, st)
        actions = self._run(words, st, plan)
        self.state = st
        return actions

    # ------------------------------------------------------------------ step 3: checks

    def _check(self, w: Words, st: GcodeState) -> dict:
        """GRBL's error checks in its order; returns what execution needs (state untouched)."""
        g, values = w.gcodes, dict(w.values)
        axis = {k: values[k] for k in "XYZ" if k in values}
        axis_command = w.axis_command
        if axis and axis_command is None:
            axis_command = "motion"  # axis words alone use the modal motion mode
        if values.get("N", 0) > MAX_LINE_NUMBER:
            raise GcodeError(27)
        inverse = (g["feedmode"] == 9300) if "feedmode" in g else st.inverse_time
        motion = g["motion"] / 100 if "motion" in g else st.motion
        inches = (g["units"] == 2000) if "units" in g else st.inches
        scale = MM_PER_INCH if inches else 1.0
        if inverse:
            if axis_command == "motion" and motion not in (0, 80) and "F" not in values:
                raise GcodeError(22)
            feed = values.get("F", 0.0)
        elif not st.inverse_time:
            feed = values["F"] * scale if "F" in values else st.feed
        else:
            feed = values["F"] * scale if "F" in values else 0.0  # G93 -> G94: undefined
        nonmodal = g.get("nonmodal")
        if nonmodal == 400:
            if "P" not in values:
                raise GcodeError(28)
            values.pop("P")
        if axis_command == "tlo" and g.get("tlo") == 4310 and set(axis) != {"Z"}:
            raise GcodeError(37)
        coord_index = g["coord"] // 100 - 54 if "coord" in g else st.coord_index
        target = list(st.position)
        mm = {k: v * scale for k, v in axis.items()}
        if nonmodal == 1000:
            if not axis:
                raise GcodeError(26)
            if "P" not in values and "L" not in values:
                raise GcodeError(28)
            if values.get("P", 0) > 6:
                raise GcodeError(29)
            if values.get("L", 0) != 20 and (values.get("L", 0) != 2 or "R" in values):
                raise GcodeError(20)
            values.pop("L", None)
            values.pop("P", None)
        elif nonmodal == 9200:
            if not axis:
                raise GcodeError(26)
        elif axis_command != "tlo" and axis:
            for i, k in enumerate("XYZ"):
                if k in mm:
                    if nonmodal == 5300:
                        target[i] = mm[k]
                    elif ((g["distance"] == 9000) if "distance" in g else st.absolute):
                        offset = st.coord_systems[coord_index][i] + st.g92[i]
                        target[i] = mm[k] + offset + (st.tool_offset if i == 2 else 0.0)
                    else:
                        target[i] = st.position[i] + mm[k]
            if nonmodal in (2800, 3000) and not axis:
                axis_command = None
            if nonmodal == 5300 and motion not in (0, 1):
                raise GcodeError(30)
        elif nonmodal in (2800, 3000):
            axis_command = None
        elif nonmodal == 5300 and motion not in (0, 1):
            raise GcodeError(30)
        arc = None
        if motion == 80:
            if axis:
                raise GcodeError(31)
        elif axis_command == "motion":
            if motion == 0:
                if not axis:
                    axis_command = None
            else:
                if feed == 0.0:
                    raise GcodeError(22)
                if motion == 1:
                    if not axis:
                        axis_command = None
                elif motion in (2, 3):
                    arc = self._check_arc(values, axis, target, st, motion == 2, scale,
                                          (g["plane"] // 100) if "plane" in g else st.plane)
                else:  # G38.2-G38.5
                    if not axis:
                        raise GcodeError(26)
                    if target == st.position:
                        raise GcodeError(33)
        for k in "NFST":
            values.pop(k, None)
        if axis_command:
            for k in "XYZ":
                values.pop(k, None)
        if values:
            raise GcodeError(36)  # a word no command on the line uses (K on a G1, L without G10...)
        return dict(axis=axis, mm=mm, axis_command=axis_command, motion=motion, feed=feed, inverse=inverse,
                    inches=inches, scale=scale, target=target, coord_index=coord_index, arc=arc)

    def _check_arc(self, values: dict, axis: dict, target: list[float], st: GcodeState, clockwise: bool,
                   scale: float, plane: int) -> tuple:
        a0, a1, _ = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}[plane]
        if not axis:
            raise GcodeError(26)
        if "XYZ"[a0] not in axis and "XYZ"[a1] not in axis:
            raise GcodeError(32)
        x, y = target[a0] - st.position[a0], target[a1] - st.position[a1]
        offset = [0.0, 0.0, 0.0]
        if "R" in values:
            r = values.pop("R") * scale
            if target == st.position:
                raise GcodeError(33)
            h = 4.0 * r * r - x * x - y * y
            if h < 0:
                raise GcodeError(34)
            h = -math.sqrt(h) / math.hypot(x, y)
            if not clockwise:
                h = -h
            if r < 0:
                h, r = -h, -r
            offset[a0], offset[a1] = 0.5 * (x - y * h), 0.5 * (y + x * h)
        else:
            if "IJK"[a0] not in values and "IJK"[a1] not in values:
                raise GcodeError(35)
            for i, k in enumerate("IJK"):
                offset[i] = values.pop(k, 0.0) * scale
            r = math.hypot(offset[a0], offset[a1])
            delta_r = abs(math.hypot(x - offset[a0], y - offset[a1]) - r)
            if delta_r > 0.005 and (delta_r > 0.5 or delta_r > 0.001 * r):
                raise GcodeError(33)
        return offset, r, plane, clockwise

    # ------------------------------------------------------------------ step 4: execution

    def _run(self, w: Words, st: GcodeState, p: dict) -> list[tuple]:
        g, m, values = w.gcodes, w.mcodes, w.values
        actions: list[tuple] = []
        laser = self.config.laser_mode
        motion, axis_command = p["motion"], p["axis_command"]
        cutting_now = motion in _CUTTING
        is_motion = laser and bool(p["axis"]) and axis_command == "motion"
        force_sync = False
        if laser and not is_motion and st.spindle == "M3":
            # M3 (constant power) must change the beam when the mode switches without motion
            force_sync = (st.motion in _CUTTING) != cutting_now
        st.inverse_time = p["inverse"]
        st.feed = p["feed"]
        s = values.get("S", st.s)
        if s != st.s or force_sync:
            if st.spindle != "M5" and not is_motion:
                actions += [("sync",), ("spindle", st.spindle, 0.0 if laser and not cutting_now else s)]
            st.s = s
        if "T" in values:
            st.tool = int(values["T"])
        if "spindle" in m:
            mode = f"M{m['spindle']}"
            if mode != st.spindle:  # every spindle state change drains the planner, even in laser mode
                actions += [("sync",), ("spindle", mode, st.s)]
                st.spindle = mode
        if "coolant" in m:
            coolant = frozenset() if m["coolant"] == 9 else st.coolant | {f"M{m['coolant']}"}
            if coolant != st.coolant:
                actions += [("sync",), ("coolant", coolant)]
                st.coolant = coolant
        nonmodal = g.get("nonmodal")
        if nonmodal == 400:
            actions += [("sync",), ("dwell", values["P"])]
        if "plane" in g:
            st.plane = g["plane"] // 100
        st.inches = p["inches"]
        if axis_command == "tlo":
            offset = p["mm"].get("Z", 0.0) if g["tlo"] == 4310 else 0.0
            st.tool_offset = offset
        if p["coord_index"] != st.coord_index:
            st.coord_index = p["coord_index"]
        if "distance" in g:
            st.absolute = g["distance"] == 9000
        if nonmodal == 1000:
            self._g10(st, values, p["mm"])
            actions += [("sync",), ("eeprom",)]
        elif nonmodal in (2800, 3000):
            stored = st.g28 if nonmodal == 2800 else st.g30
            home = [stored[i] if "XYZ"[i] in p["axis"] or not p["axis"] else p["target"][i] for i in range(3)]
            if p["axis"]:
                actions += self._line(st, p["target"], None, True)
            actions += self._line(st, home, None, True)
        elif nonmodal in (2810, 3010):
            (st.g28 if nonmodal == 2810 else st.g30)[:] = st.position
            actions += [("sync",), ("eeprom",)]
        elif nonmodal == 9200:
            st.g92 = [st.position[i] - st.coord_systems[st.coord_index][i] - p["mm"][k] if k in p["mm"]
                      else st.g92[i] for i, k in enumerate("XYZ")]
        elif nonmodal == 9210:
            st.g92 = [0.0, 0.0, 0.0]
        st.motion = motion
        if motion != 80 and axis_command == "motion":
            target = p["target"]
            start = tuple(st.position)
            if motion == 0:
                actions += self._line(st, target, None, True)
            elif motion == 1:
                actions += self._line(st, target, self._rate(st, target), False)
            elif motion in (2, 3):
                offset, radius, plane, clockwise = p["arc"]
                actions += self._arc(st, target, offset, radius, plane, clockwise)
            else:
                actions += self._line(st, target, self._rate(st, target), False)
                if motion in (38.2, 38.4):
                    actions.append(("alarm", 5))  # nothing to touch: probe fail (G38.3/.5 do not fail)
            centre = None
            if motion in (2, 3):
                centre = tuple(start[i] + p["arc"][0][i] for i in range(3))
            self.motion = Motion(int(motion), start, tuple(st.position), centre)
        if "stop" in m and m["stop"] != 1:  # M1 (optional stop) is ignored by GRBL
            actions.append(("sync",))
            if m["stop"] == 0:
                actions.append(("pause",))
            else:
                actions.append(("end",))
                st.motion, st.absolute, st.coord_index, st.plane = 1, True, 0, 17
                st.inverse_time = False
                if st.spindle != "M5":
                    actions.append(("spindle", "M5", st.s))
                st.spindle, st.coolant = "M5", frozenset()
        if st.inverse_time:
            st.feed = 0.0  # G93: the feed is implicitly zeroed after every block
        return actions

    def _simple(self, line: str) -> list[tuple] | None:
        """The general path's result for a plain G0/G1 XY line in laser mode, or None."""
        match = _SIMPLE.match(line)
        if match is None or not self.config.laser_mode:
            return None
        g, x, y, f, s = match.groups()
        st = self.state
        if (x is None and y is None) or st.inverse_time or st.motion not in (0, 1) and g is None:
            return None
        if (f is not None and f.startswith("-")) or (s is not None and s.startswith("-")):
            return None
        motion = st.motion if g is None else int(g)
        scale = MM_PER_INCH if st.inches else 1.0
        feed = float(f) * scale if f is not None else st.feed
        if motion == 1 and feed == 0.0:
            return None  # error:22, from the general path
        target = list(st.position)
        offsets = st.coord_systems[st.coord_index]
        for i, value in ((0, x), (1, y)):
            if value is not None:
                target[i] = (float(value) * scale + offsets[i] + st.g92[i] if st.absolute
                             else st.position[i] + float(value) * scale)
        start = tuple(st.position)
        if self.config.soft_limits and not self._check_travel(target):
            return None  # the alarm comes from the general path
        # nothing can fail from here on: the state is updated in place
        st.feed, st.motion = feed, motion
        if s is not None:
            st.s = float(s)  # laser mode: S on a moving line never stops the planner
        actions = self._line(st, target, None if motion == 0 else feed, motion == 0)
        self.motion = Motion(motion, start, tuple(st.position), None)
        return actions

    # ------------------------------------------------------------------ helpers

    def _rate(self, st: GcodeState, target: list[float]) -> float:
        if not st.inverse_time:
            return st.feed
        return max(math.dist(st.position, target) * st.feed, 1.0)

    def _check_travel(self, target: list[float]) -> bool:
        if not self.config.soft_limits:
            return True
        # Machine space 0..max travel per axis (HOMING_FORCE_SET_ORIGIN style, usual on lasers).
        for value, travel in zip(target, self.config.max_travel):
            if travel > 0 and not (-1e-6 <= value <= travel + 1e-6):
                return False
        return True

    def _line(self, st: GcodeState, target: list[float], feed: float | None, rapid: bool) -> list[tuple]:
        if not self._check_travel(target):
            return [("alarm", 2)]
        st.position = list(target)
        return [("move", tuple(target), feed, rapid, st.spindle, st.s)]

    def _g10(self, st: GcodeState, values: dict, mm: dict) -> None:
        level, p = int(values.get("L", 0)), int(values.get("P", 0))
        index = st.coord_index if p == 0 else p - 1
        system = list(st.coord_systems[index])
        for i, letter in enumerate("XYZ"):
            if letter in mm:
                system[i] = mm[letter] if level == 2 else st.position[i] - st.g92[i] - mm[letter]
        st.coord_systems = [list(s) for s in st.coord_systems]
        st.coord_systems[index] = system

    def _arc(self, st: GcodeState, target: list[float], offset: list[float], radius: float, plane: int,
             clockwise: bool) -> list[tuple]:
        axes = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}[plane]
        chords = arc_chords(st.position, target, offset, radius, axes, clockwise, self.config.arc_tolerance)
        feed = st.feed
        if st.inverse_time:
            a0, a1, lin = axes
            travel_len = math.hypot(chords.sweep * radius, target[lin] - st.position[lin])
            feed = max(travel_len * st.feed, 1.0)
        actions: list[tuple] = []
        for point in chords.points:
            actions += self._line(st, point, feed, False)
            if actions[-1][0] == "alarm":
                return actions
        return actions
