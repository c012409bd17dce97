"""GRBL 1.1h's G-code word reader: one cleaned line into commands and values, checked.

Step 2 of `gc_execute_line` (gnea/grbl gcode.c): every word is a letter and a number;
G and M commands go to their modal groups (two of one group: error:21); value words may
appear once (error:25); F, N, P, S and T may not be negative (error:4). Commands are
kept as code x 100 (G38.2 -> 3820) like GRBL's mantissa, so G1.5 is error:23.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field


class GcodeError(Exception):
    """A line GRBL would answer with `error:code`."""

    def __init__(self, code: int):
        super().__init__(f"error:{code}")
        self.code = code


_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")
_VALUE_LETTERS = frozenset("FIJKLNPRSTXYZ")
MAX_TOOL_NUMBER = 255

# integer G code -> modal group (gcode.c's switch); decimals are checked in _g_group
_G_GROUPS: dict[int, str] = {
    4: "nonmodal", 10: "nonmodal", 28: "nonmodal", 30: "nonmodal", 53: "nonmodal", 92: "nonmodal",
    0: "motion", 1: "motion", 2: "motion", 3: "motion", 38: "motion", 80: "motion",
    17: "plane", 18: "plane", 19: "plane", 90: "distance", 91: "distance", 93: "feedmode", 94: "feedmode",
    20: "units", 21: "units", 40: "cutter", 43: "tlo", 49: "tlo", 54: "coord", 55: "coord", 56: "coord",
    57: "coord", 58: "coord", 59: "coord", 61: "path",
}
# M7 (mist) exists only when GRBL is built with ENABLE_M7, which the default build is not
M_GROUPS: dict[int, str] = {0: "stop", 1: "stop", 2: "stop", 30: "stop", 3: "spindle", 4: "spindle",
                            5: "spindle", 8: "coolant", 9: "coolant"}


@dataclass
class Words:
    """A parsed line: `gcodes` {group: code x 100}, `mcodes` {group: code}, `values` {letter: value}."""

    gcodes: dict[str, int] = field(default_factory=dict)
    mcodes: dict[str, int] = field(default_factory=dict)
    values: dict[str, float] = field(default_factory=dict)
    axis_command: str | None = None  # None, "nonmodal", "motion", "tlo"


def _g_group(whole: int, mantissa: int, out: Words) -> str:
    """Modal group of G<whole>.<mantissa>; tracks axis commands; raises GRBL's errors."""
    group = _G_GROUPS.get(whole)
    if group is None:
        raise GcodeError(20)
    if whole in (10, 28, 30, 92) and mantissa == 0 or whole in (0, 1, 2, 3, 38, 43, 49):
        if out.axis_command is not None:
            raise GcodeError(24)  # two commands that both want the axis words
        out.axis_command = "tlo" if group == "tlo" else group
    if whole in (28, 30, 92):
        if mantissa not in (0, 10):
            raise GcodeError(20)
        return group
    if whole == 38:
        if mantissa not in (20, 30, 40, 50):
            raise GcodeError(20)  # G38.2-G38.5 probe; G38.1 does not exist
        return group
    if whole in (90, 91) and mantissa:
        if mantissa != 10 or whole == 90:
            raise GcodeError(20)  # G90.1 unsupported; G91.1 is accepted and does nothing
        return "arcdist"
    if whole == 43:
        if mantissa != 10:
            raise GcodeError(20)  # only G43.1 (dynamic tool length offset)
        return group
    if whole == 61 and mantissa:
        raise GcodeError(20)  # G61.1
    if mantissa:
        raise GcodeError(23)  # e.g. G1.5: the command must be an integer
    return group


def read_words(line: str) -> Words:
    """Parse one cleaned, upper-case line; raise `GcodeError` where GRBL's step 2 would."""
    out = Words()
    pos = 0
    for match in _WORD.finditer(line):
        if match.start() != pos:
            break
        pos = match.end()
        letter, value = match.group(1), float(match.group(2))
        whole = int(value)  # trunc, like GRBL's int_value
        mantissa = int(round(100 * (value - whole)))
        if letter == "G":
            group = _g_group(whole, mantissa, out)
            if group in out.gcodes:
                raise GcodeError(21)
            out.gcodes[group] = whole * 100 + mantissa
        elif letter == "M":
            if mantissa:
                raise GcodeError(23)
            group = M_GROUPS.get(whole)
            if group is None:
                raise GcodeError(20)
            if group in out.mcodes:
                raise GcodeError(21)
            out.mcodes[group] = whole
        elif letter in _VALUE_LETTERS:
            if letter == "T" and value > MAX_TOOL_NUMBER:
                raise GcodeError(38)
            if letter in out.values:
                raise GcodeError(25)
            if letter in "FNPST" and value < 0:
                raise GcodeError(4)
            out.values[letter] = value
        else:
            raise GcodeError(20)
    if pos != len(line):
        # GRBL: a non-letter where a word should start is error:1; a letter without a
        # readable number after it is error:2
        raise GcodeError(2 if "A" <= line[pos] <= "Z" else 1)
    return out
