"""A G-code file ready to stream: cleaned lines with their file line numbers, and what
the job does (extent, max S, laser use, planner-model time per line).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from machines.gcode_interpreter import GcodeError, GcodeInterpreter, GcodeState, MachineConfig
from machines.grbl_codes import describe_error
from machines.grbl_protocol import MAX_LINE_CHARS, clean_line
from machines.planner_model import BlockBuilder, Kinematics, block_durations
from onestroke.errors import InputError
from onestroke.textfile import read_text


@dataclass(frozen=True)
class Program:
    """Lines to send: `lines[i]` is (file line number, 1-based; cleaned text). Blank and
    comment-only lines are left out (they would only cost an `ok` round trip)."""

    source: str
    lines: tuple[tuple[int, str], ...]

    def __len__(self) -> int:
        return len(self.lines)


def program_from_text(text: str, *, source: str = "<text>") -> Program:
    """Clean every line; InputError naming the first line GRBL would refuse as too long."""
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        clean = clean_line(raw)
        if not clean:
            continue
        if len(clean) > MAX_LINE_CHARS:
            raise InputError(f"{source} line {number} has {len(clean)} characters after removing spaces "
                             f"and comments; GRBL accepts at most {MAX_LINE_CHARS}")
        if not clean.isascii():
            raise InputError(f"{source} line {number} {raw.strip()[:40]!r} has non-ASCII characters; "
                             "GRBL reads plain ASCII G-code")
        lines.append((number, clean))
    return Program(source, tuple(lines))


def load_program(path: str | os.PathLike) -> Program:
    """Read a G-code file (UTF-8 text) into a `Program`; InputError if unreadable."""
    name = str(path)
    text = read_text(path, what="G-code file", expect="a .gcode/.nc file")
    program = program_from_text(text, source=name)
    if not program.lines:
        raise InputError(f"G-code file {name!r} has no G-code lines")
    return program


@dataclass(frozen=True)
class ProgramStats:
    """What a program does on a given machine.

    extent: ((xmin, ymin), (xmax, ymax)) in machine mm of every position reached (None if
    nothing moves); burn_extent the same for moves with the beam on. max_s: largest S.
    uses_laser: M3/M4 with S > 0 somewhere. line_seconds: (len(program),) planner-model
    seconds up to the end of each program line (cumulative). errors: (file line, text)
    for lines GRBL would refuse.
    """

    extent: tuple[tuple[float, float], tuple[float, float]] | None
    burn_extent: tuple[tuple[float, float], tuple[float, float]] | None
    max_s: float
    uses_laser: bool
    line_seconds: np.ndarray
    errors: tuple[tuple[int, str], ...]

    @property
    def total_seconds(self) -> float:
        return float(self.line_seconds[-1]) if len(self.line_seconds) else 0.0


def analyze_program(program: Program, *, settings: dict[int, float] | None = None,
                    start: Sequence[float] = (0.0, 0.0, 0.0),
                    offsets: dict[str, Sequence[float]] | None = None,
                    planner_blocks: int = 15) -> ProgramStats:
    """Interpret `program` as GRBL would with `settings` ($$), from machine position `start`
    (mm) and work offsets from `$#` ({"G54": (x, y, z), ..., "G92": ...})."""
    settings = settings or {}
    kin = Kinematics.from_settings(settings, planner_blocks=planner_blocks)
    config = MachineConfig(laser_mode=bool(settings.get(32, 1)), soft_limits=False,
                           arc_tolerance=settings.get(12, 0.002))
    state = GcodeState(position=[float(v) for v in start])
    for i in range(6):
        if offsets and f"G{54 + i}" in offsets:
            state.coord_systems[i] = [float(v) for v in offsets[f"G{54 + i}"]]
    if offsets and "G92" in offsets:
        state.g92 = [float(v) for v in offsets["G92"]]
    interp = GcodeInterpreter(config, state)
    builder = BlockBuilder(kin)
    items: list = []
    owner: list[int] = []
    points: list[tuple[float, float]] = []
    burn: list[tuple[float, float]] = []
    max_s, uses_laser, errors = 0.0, False, []
    rest = True
    position = list(state.position)
    for index, (number, text) in enumerate(program.lines):
        if text.startswith("$"):
            continue
        try:
            actions = interp.execute(text)
        except GcodeError as error:
            if len(errors) < 20:
                errors.append((number, f"{text}: {describe_error(error.code)}"))
            continue
        for action in actions:
            kind = action[0]
            if kind == "move":
                _, target, feed, rapid, mode, s = action
                block = builder.make(position, target, feed_mm_min=feed, rapid=rapid, from_rest=rest)
                if block is not None:
                    items.append(block)
                    owner.append(index)
                    rest = False
                    if mode != "M5" and s > 0 and not rapid:
                        burn += [(position[0], position[1]), (target[0], target[1])]
                        uses_laser = True
                position = list(target)
                points.append((target[0], target[1]))
                max_s = max(max_s, s)
            elif kind in ("sync", "end", "pause"):
                items.append(None)
                owner.append(index)
                rest = True
            elif kind == "dwell":
                items.append(float(action[1]))
                owner.append(index)
                rest = True
            elif kind == "spindle":
                max_s = max(max_s, action[2])
    seconds = block_durations(items, window=kin.planner_blocks) if items else np.zeros(0)
    per_line = np.bincount(np.asarray(owner, dtype=int), weights=seconds, minlength=len(program)) \
        if items else np.zeros(len(program))
    points_all = points + [(float(start[0]), float(start[1]))] if points else []

    def box(pts):
        if not pts:
            return None
        arr = np.asarray(pts)
        return (tuple(arr.min(axis=0).tolist()), tuple(arr.max(axis=0).tolist()))

    return ProgramStats(box(points_all), box(burn), max_s, uses_laser, np.cumsum(per_line), tuple(errors))
