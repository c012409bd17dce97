"""GRBL 1.1 G-code semantics: one cleaned line in, the actions the firmware would take out.

Shared by the emulator (to execute lines) and by job analysis (bounding box, max S, time
estimate), so both read G-code exactly the same way. Positions are machine coordinates
in mm, shape (3,). Arcs come out as the same short chords GRBL cuts them into ($12).
"""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field

MM_PER_INCH = 25.4
ARC_EPSILON = 5e-7

# Action tuples (kept as tuples: the emulator runs tens of thousands per job).
#   ("move", target(3,), feed_mm_min | None, rapid, spindle_mode, s)
#   ("sync",)                     planner drains before the next action
#   ("eeprom",)                   GRBL writes EEPROM now (serial input is lost meanwhile)
#   ("dwell", seconds)
#   ("spindle", mode, s)          mode in "M3", "M4", "M5"
#   ("coolant", frozenset of "M7"/"M8")
#   ("pause",)                    M0/M1: feed hold once the planner drains
#   ("end",)                      M2/M30: program end
#   ("alarm", code)               soft limit (ALARM:2)


class GcodeError(Exception):
    """A line GRBL would answer with `error:code`."""

    def __init__(self, code: int):
        super().__init__(f"error:{code}")
        self.code = code


@dataclass
class GcodeState:
    """The parser's modal state (mutable; the interpreter copies it per line)."""

    position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    motion: int = 0  # 0, 1, 2, 3, 80 (G38.x is refused)
    absolute: bool = True
    inches: bool = False
    plane: int = 17
    inverse_time: bool = False
    coord_index: int = 0  # G54 = 0 ... G59 = 5
    coord_systems: list[list[float]] = field(default_factory=lambda: [[0.0] * 3 for _ in range(6)])
    g92: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    g28: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    g30: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    spindle: str = "M5"
    s: float = 0.0
    feed: float = 0.0  # mm/min (or 1/min in G93); 0 = undefined
    coolant: frozenset = frozenset()

    def modal_report(self) -> str:
        """The body of a `[GC:...]` reply."""
        coolant = " ".join(sorted(self.coolant)) or "M9"
        feed = self.feed / (MM_PER_INCH if self.inches else 1.0)
        return (f"G{self.motion} G{54 + self.coord_index} G{self.plane} G{20 if self.inches else 21} "
                f"G{90 if self.absolute else 91} G{93 if self.inverse_time else 94} {self.spindle} "
                f"{coolant} T0 F{feed:g} S{self.s:g}")


_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")
_VALUE_LETTERS = set("FIJKLNPRSTXYZ")
_G_GROUPS = {  # code*10 -> modal group (mantissa-aware)
    40: "nonmodal", 100: "nonmodal", 280: "nonmodal", 281: "nonmodal", 300: "nonmodal", 301: "nonmodal",
    530: "nonmodal", 920: "nonmodal", 921: "nonmodal",
    0: "motion", 10: "motion", 20: "motion", 30: "motion", 800: "motion",
    170: "plane", 180: "plane", 190: "plane", 900: "distance", 910: "distance", 911: "arcdist",
    930: "feedmode", 940: "feedmode", 200: "units", 210: "units", 400: "cutter", 431: "tlo", 490: "tlo",
    540: "coord", 550: "coord", 560: "coord", 570: "coord", 580: "coord", 590: "coord", 610: "path",
}
_M_GROUPS = {0: "stop", 1: "stop", 2: "stop", 30: "stop", 3: "spindle", 4: "spindle", 5: "spindle",
             7: "coolant", 8: "coolant", 9: "coolant"}


@dataclass(frozen=True, kw_only=True)
class MachineConfig:
    """What the interpreter needs from the settings: laser mode, soft limits and travel (mm)."""

    laser_mode: bool = True
    soft_limits: bool = False
    max_travel: tuple[float, float, float] = (400.0, 400.0, 0.0)
    arc_tolerance: float = 0.002


class GcodeInterpreter:
    """Executes cleaned lines against a `GcodeState`; raises `GcodeError` like GRBL would."""

    def __init__(self, config: MachineConfig = MachineConfig(), state: GcodeState | None = None):
        self.config = config
        self.state = state or GcodeState()

    def reset_modal(self) -> None:
        """Soft reset: modal state back to defaults, position and stored offsets kept."""
        old = self.state
        self.state = GcodeState(position=list(old.position), coord_systems=old.coord_systems,
                                g28=old.g28, g30=old.g30)

    def execute(self, line: str) -> list[tuple]:
        """Interpret one cleaned, upper-case line; return its actions and commit the state."""
        st = copy.copy(self.state)
        st.position = list(st.position)
        st.g92 = list(st.g92)
        if not line:
            return []
        pos = 0
        words: dict[str, float] = {}
        gcodes: dict[str, int] = {}
        mcodes: dict[str, int] = {}
        for match in _WORD.finditer(line):
            if match.start() != pos:
                raise GcodeError(1 if not line[pos].isalpha() else 2)
            pos = match.end()
            letter, text = match.group(1), match.group(2)
            value = float(text)
            if letter == "G":
                code10 = int(round(value * 10))
                if code10 // 10 == 38:
                    raise GcodeError(20)  # probing: not on a laser
                group = _G_GROUPS.get(code10)
                if group is None:
                    raise GcodeError(23 if code10 % 10 and (code10 // 10 * 10) in _G_GROUPS else 20)
                if group in gcodes:
                    raise GcodeError(21)
                gcodes[group] = code10
            elif letter == "M":
                if value != int(value):
                    raise GcodeError(20)
                group = _M_GROUPS.get(int(value))
                if group is None:
                    raise GcodeError(20)
                if group in mcodes:
                    raise GcodeError(21)
                mcodes[group] = int(value)
            elif letter in _VALUE_LETTERS:
                if letter in words:
                    raise GcodeError(25)
                if letter in "FNPST" and value < 0:
                    raise GcodeError(4)
                words[letter] = value
            else:
                raise GcodeError(20)
        if pos != len(line):
            raise GcodeError(1 if not line[pos].isalpha() else 2)

        actions: list[tuple] = []
        scale = MM_PER_INCH if gcodes.get("units", 200 if st.inches else 210) == 200 else 1.0
        nonmodal = gcodes.get("nonmodal")
        axis = {k: words[k] for k in "XYZ" if k in words}
        motion = gcodes.get("motion")
        if nonmodal in (100, 280, 300, 920) and axis:
            if motion is not None:
                raise GcodeError(24)
            axis_for_motion = False
        else:
            axis_for_motion = bool(axis)
        if "N" in words and words["N"] > 9999999:
            raise GcodeError(27)

        # Order of execution follows gc_execute_line.
        if "feedmode" in gcodes:
            st.inverse_time = gcodes["feedmode"] == 930
        new_motion = st.motion if motion is None else motion // 10
        if "F" in words:
            st.feed = words["F"] * (1.0 if st.inverse_time else scale)
        elif st.inverse_time and axis_for_motion and new_motion in (1, 2, 3):
            raise GcodeError(22)
        laser = self.config.laser_mode
        has_motion_words = axis_for_motion and new_motion in (0, 1, 2, 3)
        if "S" in words and words["S"] != st.s:
            force = not (laser and has_motion_words and new_motion in (1, 2, 3))
            if st.spindle != "M5" and force:
                actions += [("sync",), ("spindle", st.spindle, words["S"])]
            st.s = words["S"]
        if "spindle" in mcodes:
            mode = f"M{mcodes['spindle']}"
            if mode != st.spindle:
                actions += [("sync",), ("spindle", mode, st.s)]
                st.spindle = mode
        if "coolant" in mcodes:
            code = mcodes["coolant"]
            coolant = frozenset() if code == 9 else st.coolant | {f"M{code}"}
            if coolant != st.coolant:
                actions += [("sync",), ("coolant", coolant)]
                st.coolant = coolant
        if nonmodal == 40:
            if "P" not in words:
                raise GcodeError(28)
            actions += [("sync",), ("dwell", words["P"])]
        if "plane" in gcodes:
            st.plane = gcodes["plane"] // 10
        if "units" in gcodes:
            st.inches = gcodes["units"] == 200
        if "coord" in gcodes:
            index = gcodes["coord"] // 10 - 54
            if index != st.coord_index:
                actions.append(("sync",))
            st.coord_index = index
        if "distance" in gcodes:
            st.absolute = gcodes["distance"] == 900

        def work_target(base: list[float], use_offsets: bool = True) -> list[float]:
            target = list(base)
            for i, letter in enumerate("XYZ"):
                if letter in axis:
                    value = axis[letter] * scale
                    if st.absolute or nonmodal == 530:
                        offset = (st.coord_systems[st.coord_index][i] + st.g92[i]) if use_offsets else 0.0
                        target[i] = value + offset
                    else:
                        target[i] = st.position[i] + value
            return target

        if nonmodal == 100:
            self._g10(st, words, axis, scale)
            actions += [("sync",), ("eeprom",)]
        elif nonmodal in (280, 300):
            stored = st.g28 if nonmodal == 280 else st.g30
            if axis:
                mid = work_target(st.position)
                actions += self._line(st, mid, None, True)
            actions += self._line(st, list(stored), None, True)
        elif nonmodal in (281, 301):
            (st.g28 if nonmodal == 281 else st.g30)[:] = st.position
            actions += [("sync",), ("eeprom",)]
        elif nonmodal == 920:
            if not axis:
                raise GcodeError(26)
            for i, letter in enumerate("XYZ"):
                if letter in axis:
                    st.g92[i] = st.position[i] - st.coord_systems[st.coord_index][i] - axis[letter] * scale
            actions.append(("sync",))
        elif nonmodal == 921:
            st.g92 = [0.0, 0.0, 0.0]
            actions.append(("sync",))

        if motion is not None:
            st.motion = motion // 10
        if axis_for_motion:
            if st.motion == 80:
                raise GcodeError(31)
            if nonmodal == 530 and st.motion not in (0, 1):
                raise GcodeError(30)
            target = work_target(st.position, use_offsets=nonmodal != 530)
            if st.motion in (1, 2, 3) and st.feed <= 0:
                raise GcodeError(22)
            if st.motion == 0:
                actions += self._line(st, target, None, True)
            elif st.motion == 1:
                actions += self._line(st, target, self._rate(st, target), False)
            else:
                actions += self._arc(st, target, words, scale)
        elif motion is not None and motion in (20, 30) and not axis:
            raise GcodeError(26)
        elif any(k in words for k in "IJKR") and st.motion not in (2, 3):
            raise GcodeError(36)

        if "stop" in mcodes:
            code = mcodes["stop"]
            actions.append(("sync",))
            if code in (0, 1):
                actions.append(("pause",))
            else:
                actions.append(("end",))
                st.motion, st.absolute, st.coord_index, st.plane = 1, True, 0, 17
                st.inverse_time, st.g92 = False, [0.0, 0.0, 0.0]
                if st.spindle != "M5":
                    actions.append(("spindle", "M5", st.s))
                st.spindle, st.coolant = "M5", frozenset()
        self.state = st
        return actions

    # ------------------------------------------------------------------ helpers

    def _rate(self, st: GcodeState, target: list[float]) -> float:
        if not st.inverse_time:
            return st.feed
        length = math.dist(st.position, target)
        return max(length * st.feed, 1.0)

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

    def _g10(self, st: GcodeState, words: dict, axis: dict, scale: float) -> None:
        if "L" not in words or "P" not in words:
            raise GcodeError(28)
        level, p = int(words["L"]), int(words["P"])
        if level not in (2, 20) or not 0 <= p <= 6:
            raise GcodeError(20 if level not in (2, 20) else 29)
        index = st.coord_index if p == 0 else p - 1
        system = list(st.coord_systems[index])
        for i, letter in enumerate("XYZ"):
            if letter in axis:
                value = axis[letter] * scale
                system[i] = value if level == 2 else st.position[i] - st.g92[i] - value
        st.coord_systems = [list(s) for s in st.coord_systems]
        st.coord_systems[index] = system

    def _arc(self, st: GcodeState, target: list[float], words: dict, scale: float) -> list[tuple]:
        a0, a1, lin = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}[st.plane]
        letters = "XYZ"
        if letters[a0] not in words and letters[a1] not in words:
            raise GcodeError(32)
        clockwise = st.motion == 2
        start = st.position
        offset = [0.0, 0.0, 0.0]
        if "R" in words:
            r = words["R"] * scale
            x, y = target[a0] - start[a0], target[a1] - start[a1]
            if abs(x) < 1e-9 and abs(y) < 1e-9:
                raise GcodeError(33)
            h = 4.0 * r * r - x * x - y * y
            if h < 0:
                raise GcodeError(33)
            h = -math.sqrt(h) / math.hypot(x, y)
            if not clockwise:
                h = -h
            if r < 0:
                h, r = -h, -r
            offset[a0], offset[a1] = 0.5 * (x - y * h), 0.5 * (y + x * h)
            radius = r
        else:
            ijk = "IJK"
            if ijk[a0] not in words and ijk[a1] not in words:
                raise GcodeError(35)
            for i, letter in enumerate(ijk):
                offset[i] = words.get(letter, 0.0) * scale
            radius = math.hypot(offset[a0], offset[a1])
            target_r = math.hypot(target[a0] - start[a0] - offset[a0], target[a1] - start[a1] - offset[a1])
            delta_r = abs(target_r - radius)
            if delta_r > 0.005 and (delta_r > 0.5 or delta_r > 0.001 * radius):
                raise GcodeError(33)
        center0, center1 = start[a0] + offset[a0], start[a1] + offset[a1]
        r0, r1 = -offset[a0], -offset[a1]
        rt0, rt1 = target[a0] - center0, target[a1] - center1
        travel = math.atan2(r0 * rt1 - r1 * rt0, r0 * rt0 + r1 * rt1)
        if clockwise and travel >= -ARC_EPSILON:
            travel -= 2 * math.pi
        elif not clockwise and travel <= ARC_EPSILON:
            travel += 2 * math.pi
        tol = self.config.arc_tolerance
        segments = int(math.floor(abs(0.5 * travel * radius) / math.sqrt(tol * (2 * radius - tol)))) \
            if radius > tol else 0
        arc_length = math.hypot(abs(travel) * radius, target[lin] - start[lin])
        feed = st.feed if not st.inverse_time else max(arc_length * st.feed, 1.0)
        actions: list[tuple] = []
        for i in range(1, segments):
            theta = travel * i / segments
            point = list(start)
            c, s = math.cos(theta), math.sin(theta)
            point[a0] = center0 + r0 * c - r1 * s
            point[a1] = center1 + r0 * s + r1 * c
            point[lin] = start[lin] + (target[lin] - start[lin]) * i / segments
            actions += self._line(st, point, feed, False)
            if actions[-1][0] == "alarm":
                return actions
        actions += self._line(st, target, feed, False)
        return actions
