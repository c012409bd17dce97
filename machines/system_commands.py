"""GRBL 1.1h's `$` system commands as a job would meet them: what the firmware answers to
each, and which ones a job may not carry even when `$` lines are allowed.

Follows gnea/grbl 1.1h `system_execute_line` (system.c), `settings_store_global_setting`
(settings.c) and the jog checks of `gc_execute_line` (gcode.c), with the default build
(no single-axis homing, restore and build-info commands enabled, no step-rate check).
GRBL runs every `$` command but `$$`, `$G`, `$C`, `$X` and `$J=` only while Idle (or in
ALARM): streamed behind moves still running, it answers `error:8`.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from machines.gcode_words import GcodeError, read_words

# Lines GRBL accepts that change what the rest of the job means: refused by name.
CHANGES_THE_JOB = (
    (re.compile(r"^\$C$"), "switches GRBL's check mode on or off: the lines after it would move nothing, or "
                           "leaving it resets the machine mid-job"),
    (re.compile(r"^\$SLP$"), "puts GRBL to sleep: it stops and takes no more lines until reset"),
    (re.compile(r"^\$RST="), "restores GRBL's defaults and resets it: the settings and offsets the rest of the "
                             "job relies on are gone"),
    (re.compile(r"^\$N\d"), "stores a startup line that GRBL runs after every reset and $H, inside this job too"),
    (re.compile(r"^\$N$"), "prints the startup lines, which are no answers a sender can read mid-job"),
    (re.compile(r"^\$J="), "jogs: GRBL refuses (error:9) every G-code line that arrives while the jog runs"),
)
# $N settings GRBL 1.1h stores (settings.c): the others answer error:3.
KNOWN_SETTINGS = frozenset({0, 1, 2, 3, 4, 5, 6, 10, 11, 12, 13, 20, 21, 22, 23, 24, 25, 26, 27, 30, 31, 32,
                            100, 101, 102, 110, 111, 112, 120, 121, 122, 130, 131, 132})
_FLOAT = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")  # GRBL's read_float: no exponent


@dataclass(frozen=True)
class SystemAnswer:
    """GRBL's answer to one `$` line: `code` 0 for ok, else `error:code`; `refused` why a job
    may not carry it though GRBL accepts it; `setting` the ($N, value) it stores; `homes`
    True for a homing cycle (the machine position becomes home, 0)."""

    code: int = 0
    refused: str | None = None  # set whatever `code` is: the job may not carry the line anyway
    setting: tuple[int, float] | None = None
    homes: bool = False


def _jog_error(line: str) -> int:
    """GRBL's error code for a `$J=` line (0 if valid): word errors, then F missing or zero
    (22), words a jog does not use (36), commands other than G90/G91/G20/G21/G53 (16)."""
    try:
        words = read_words(line[3:])
    except GcodeError as error:
        return error.code
    if not words.values.get("F"):
        return 22
    if set(words.values) - set("NFXYZ"):
        return 36
    if words.mcodes or set(words.gcodes) - {"distance", "units", "nonmodal"} or \
            words.gcodes.get("nonmodal", 5300) != 5300:
        return 16
    return 0


def _setting_error(number: float, value: float, settings: Mapping[int, float]) -> int:
    """settings_store_global_setting's answer to `$number=value` (0: stored)."""
    whole = int(number)
    if value < 0:
        return 4
    if whole not in KNOWN_SETTINGS:
        return 3
    if whole == 0 and int(value) < 3:
        return 6
    if whole == 20 and int(value) and not settings.get(22):
        return 10  # soft limits need homing
    return 0


def system_answer(line: str, settings: Mapping[int, float], *, idle: bool) -> SystemAnswer:
    """What GRBL 1.1h answers to the cleaned `$` line `line` with these `$$` settings, the
    machine Idle (`idle`) or still running earlier moves; and whether a job may carry it."""
    refused = next((why for pattern, why in CHANGES_THE_JOB if pattern.match(line)), None)
    head = line[1:2]
    if head == "":
        return SystemAnswer(refused=refused)  # help
    if head == "J":
        code = 8 if not idle else 3 if line[2:3] != "=" else _jog_error(line)
        return SystemAnswer(code, refused)
    if head in "$GCX":
        code = 3 if len(line) > 2 else 8 if head in "$C" and not idle else 0
        return SystemAnswer(code, refused)
    if not idle:
        return SystemAnswer(8, refused)
    if head == "#":
        return SystemAnswer(3 if len(line) > 2 else 0)
    if head == "H":
        if not settings.get(22):
            return SystemAnswer(5)
        return SystemAnswer(3) if len(line) > 2 else SystemAnswer(homes=True)
    if head == "S":
        return SystemAnswer(0 if line == "$SLP" else 3, refused)
    if head == "I":
        return SystemAnswer(0 if len(line) == 2 or line[2] == "=" else 3)
    if head == "R":
        ok = len(line) == 6 and line.startswith("$RST=") and line[5] in "$#*"
        return SystemAnswer(0 if ok else 3, refused)
    if head == "N" and len(line) == 2:
        return SystemAnswer(refused=refused)
    start = 2 if head == "N" else 1
    number = _FLOAT.match(line, start)
    if number is None:
        return SystemAnswer(2)  # e.g. $Q: GRBL reads a setting number and finds none
    rest = line[number.end():]
    if not rest.startswith("="):
        return SystemAnswer(3)
    if head == "N":  # $Nx=line: a startup line, checked as G-code before it is stored
        try:
            read_words(rest[1:])
        except GcodeError as error:
            return SystemAnswer(error.code, refused)
        return SystemAnswer(refused=refused)
    value = _FLOAT.match(rest, 1)
    if value is None:
        return SystemAnswer(2)
    if value.end() != len(rest) or float(number.group()) > 255:
        return SystemAnswer(3)
    parameter, stored = float(number.group()), float(value.group())
    code = _setting_error(parameter, stored, settings)
    return SystemAnswer(code, setting=(int(parameter), stored) if code == 0 else None)
