"""A G-code program read the way GRBL 1.1h reads it: cleaned lines with their file line
numbers, then what the job does (moves, planner blocks, extent, max S, refused lines).

`analyze_program` is the one pass every consumer shares: the pre-check (`errors`), the
sender's job check and ETA, the time estimate (`machines.job_time`) and the preview.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from machines.gcode_batch import PlainRun, read_plain_run, split_plain
from machines.gcode_interpreter import GcodeError, GcodeInterpreter, GcodeState, MachineConfig
from machines.grbl_codes import describe_error
from machines.grbl_protocol import MAX_LINE_CHARS, clean_line
from machines.planner_model import Kinematics, plan_times
from machines.system_commands import system_answer
from onestroke.errors import InputError
from onestroke.progress import ProgressCallback, Stage
from onestroke.textfile import read_text

SETTINGS_REFUSED = ("a '$' system command inside a job (e.g. $RST=* resets every setting, $32=0 leaves the beam "
                    "on during travel): remove it, or pass --allow-settings if it is meant")


@dataclass(frozen=True)
class Program:
    """Lines to send: `lines[i]` is (file line number, 1-based; cleaned text). Blank and
    comment-only lines are left out (they would only cost an `ok` round trip).
    `n_lines` counts every line of the source, blank ones included."""

    source: str
    lines: tuple[tuple[int, str], ...]
    n_lines: int = 0

    def __len__(self) -> int:
        return len(self.lines)


# printable ASCII without '(', ')', '/', ';' (clean_line's _PLAIN), lines split by '\n' only
_CLEAN_TEXT = re.compile(r"[!-'*-.0-:<-~\n]*\Z")


def program_from_text(text: str, *, source: str = "<text>") -> Program:
    """Clean every line; InputError naming the first line GRBL would refuse as too long."""
    if _CLEAN_TEXT.match(text):  # the usual case (files onestroke writes): nothing to strip
        raw_lines = text.upper().split("\n")
        if raw_lines[-1] == "":
            raw_lines.pop()  # what splitlines() does with a final line end
        if max(map(len, raw_lines), default=0) <= MAX_LINE_CHARS:
            numbered = zip(range(1, len(raw_lines) + 1), raw_lines)
            if "" in raw_lines or "%" in raw_lines:
                numbered = ((number, clean) for number, clean in numbered if clean and clean != "%")
            return Program(source, tuple(numbered), len(raw_lines))
    lines = []
    raw_lines = text.splitlines()
    for number, raw in enumerate(raw_lines, start=1):
        clean = clean_line(raw)
        if not clean or clean == "%":  # '%' marks a program's start/end on tape; senders drop it
            continue
        if len(clean) > MAX_LINE_CHARS:
            raise InputError(f"{source} line {number} has {len(clean)} characters after removing spaces "
                             f"and comments; GRBL accepts at most {MAX_LINE_CHARS}")
        if not clean.isascii():
            raise InputError(f"{source} line {number} {raw.strip()[:40]!r} has non-ASCII characters; "
                             "GRBL reads plain ASCII G-code")
        lines.append((number, clean))
    return Program(source, tuple(lines), len(raw_lines))


def program_from_lines(lines: Sequence[str], *, source: str = "<lines>") -> Program:
    """`program_from_text` for a list of lines (without line ends)."""
    return program_from_text("\n".join(lines), source=source)


def load_program(path: str | os.PathLike) -> Program:
    """Read a G-code file (UTF-8 text) into a `Program`; InputError if unreadable."""
    name = str(path)
    text = read_text(path, what="G-code file", expect="a .gcode/.nc file")
    if text.lstrip("\ufeff \t\r\n").startswith("<"):  # G-code never starts with '<'; XML always does
        kind = "an SVG drawing" if "<svg" in text[:4096].lower() else "XML (or HTML)"
        raise InputError(f"G-code file {name!r} is {kind}, not G-code; make G-code from a drawing with "
                         "'onestroke laser DRAWING -o JOB.gcode'")
    program = program_from_text(text, source=name)
    if not program.lines:
        raise InputError(f"G-code file {name!r} has no G-code lines")
    return program


@dataclass(frozen=True)
class GcodeMoves:
    """Every motion command of a program as written (arcs whole), machine mm, XY.

    kind (M,) int8: 0 rapid G0, 1 G1, 2 G2 (clockwise), 3 G3, 38 probe. start, end,
    centre (M, 2) (centre NaN unless an arc). feed (M,) mm/min (NaN for G0). power (M,)
    S. laser_on (M,) the beam can fire (M3/M4, S > 0, not G0). line (M,) 0-based index
    of the source line.
    """

    kind: np.ndarray
    start: np.ndarray
    end: np.ndarray
    centre: np.ndarray
    feed: np.ndarray
    power: np.ndarray
    laser_on: np.ndarray
    line: np.ndarray

    def __len__(self) -> int:
        return len(self.kind)


@dataclass(frozen=True)
class Segments:
    """The straight moves GRBL plans (arcs cut into chords), in order.

    start, end (B, 3) mm; feed (B,) mm/min (NaN for rapids); rapid (B,); stop_before (B,)
    the planner drains before it; move (B,) index into `GcodeMoves`; index (B,) index
    into `Program.lines`; seconds (B,) planner-model seconds (batch driver).
    """

    start: np.ndarray
    end: np.ndarray
    feed: np.ndarray
    rapid: np.ndarray
    stop_before: np.ndarray
    move: np.ndarray
    index: np.ndarray
    seconds: np.ndarray

    def __len__(self) -> int:
        return len(self.rapid)


@dataclass(frozen=True)
class ProgramStats:
    """What a program does on a given machine.

    extent: ((xmin, ymin), (xmax, ymax)) in machine mm of every position reached (None if
    nothing moves); burn_extent the same for moves with the beam on. max_s: largest S.
    uses_laser: M3/M4 with S > 0 somewhere. line_seconds: (len(program),) planner-model
    seconds up to the end of each program line (cumulative). errors: (file line, text)
    for lines GRBL would refuse (or `$` commands when not allowed), in file order; codes
    the matching GRBL error codes (0 for a refused `$` command). dwell: (len(program),)
    seconds of G4 on each line. syncs: (len(program),) the line drains the planner (its
    `ok` waits for the machine to stop). settings_written: {$N: value} the job's own `$N=`
    lines store (allowed `$` lines only), in effect for the lines after them.
    """

    extent: tuple[tuple[float, float], tuple[float, float]] | None
    burn_extent: tuple[tuple[float, float], tuple[float, float]] | None
    max_s: float
    uses_laser: bool
    line_seconds: np.ndarray
    errors: tuple[tuple[int, str], ...]
    codes: tuple[int, ...]
    moves: GcodeMoves
    segments: Segments
    dwell: np.ndarray
    syncs: np.ndarray
    settings_written: Mapping[int, float] = field(default_factory=dict)

    @property
    def total_seconds(self) -> float:
        return float(self.line_seconds[-1]) if len(self.line_seconds) else 0.0


def _box(points) -> tuple[tuple[float, float], tuple[float, float]] | None:
    if not len(points):
        return None
    arr = np.asarray(points, dtype=float)
    return (tuple(arr.min(axis=0).tolist()), tuple(arr.max(axis=0).tolist()))


class _Columns:
    """Segments and moves in program order: rows from the interpreter, runs from `read_plain_run`."""

    def __init__(self) -> None:
        self.seg: list[tuple] = []  # (start, end, feed, rapid, stop_before, move, index, burn)
        self.mv: list[tuple] = []  # (kind, start, end, centre, feed, power, laser_on, line)
        self.seg_chunks: list[tuple] = []
        self.mv_chunks: list[tuple] = []
        self.moves_done = 0

    def n_moves(self) -> int:
        return self.moves_done + len(self.mv)

    def _flush(self) -> None:
        if self.seg:
            cols = list(zip(*self.seg))
            self.seg_chunks.append((np.array(cols[0], dtype=float).reshape(-1, 3),
                                    np.array(cols[1], dtype=float).reshape(-1, 3),
                                    *(np.array(c, dtype=t) for c, t in zip(cols[2:], (float, bool, bool, int, int, bool)))))
            self.seg = []
        if self.mv:
            cols = list(zip(*self.mv))
            self.mv_chunks.append((np.array(cols[0], dtype=np.int8),
                                   *(np.array(c, dtype=float).reshape(-1, 2) for c in cols[1:4]),
                                   *(np.array(c, dtype=t) for c, t in zip(cols[4:], (float, float, bool, int)))))
            self.moves_done += len(self.mv)
            self.mv = []

    def add_run(self, run: PlainRun, index: int, file_line: np.ndarray, stop_before: bool, spindle: str) -> None:
        """A plain run starting at program line `index`, file lines `file_line` (0-based):
        each line is one move and one segment."""
        self._flush()
        n = run.n
        line = np.arange(index, index + n)
        stops = np.zeros(n, dtype=bool)
        stops[0] = stop_before
        lit = (spindle != "M5") & (run.s > 0)
        burn = lit & ~run.rapid
        move = np.arange(self.moves_done, self.moves_done + n)
        self.seg_chunks.append((run.start, run.end, run.feed, run.rapid, stops, move, line, burn))
        self.mv_chunks.append((run.rapid.astype(np.int8) ^ 1, run.start[:, :2], run.end[:, :2],
                               np.full((n, 2), np.nan), run.feed, run.s, burn, file_line))
        self.moves_done += n

    def arrays(self) -> tuple[tuple, GcodeMoves]:
        """(segment columns, `GcodeMoves`); move lines are 0-based source line numbers."""
        self._flush()
        empty_seg = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=bool),
                     np.zeros(0, dtype=bool), np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0, dtype=bool))
        seg = tuple(np.concatenate(c) for c in zip(*self.seg_chunks)) if self.seg_chunks else empty_seg
        empty_mv = (np.zeros(0, dtype=np.int8), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2)),
                    np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool), np.zeros(0, dtype=int))
        mv = list(np.concatenate(c) for c in zip(*self.mv_chunks)) if self.mv_chunks else list(empty_mv)
        return seg, GcodeMoves(*mv)


def analyze_program(program: Program, *, settings: Mapping[int, float] | None = None,
                    start: Sequence[float] = (0.0, 0.0, 0.0),
                    offsets: Mapping[str, Sequence[float]] | None = None,
                    planner_blocks: int = 15, allow_settings: bool = True,
                    progress: ProgressCallback | None = None) -> ProgramStats:
    """Interpret `program` as GRBL 1.1h would with `settings` ($$), from machine position
    `start` (mm) and work offsets from `$#` ({"G54": (x, y, z), ..., "G92": ...}).

    allow_settings: False reports every `$` line as an error (a job should not change
    the machine's settings); True checks each as GRBL 1.1h would (`system_commands`: its
    error codes, `error:8` for a command that needs Idle streamed behind moves) and reports
    the ones that change what the job means ($C, $SLP, $RST, $N, $J=) by name; a stored
    setting holds for the lines after it, a homing cycle moves the head home.
    progress: an `onestroke.progress.ProgressCallback` (lines read).
    """
    settings = dict(settings or {})
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
    cols = _Columns()
    dwell = np.zeros(len(program))
    syncs = np.zeros(len(program), dtype=bool)
    max_s = 0.0
    errors, codes = [], []
    position = tuple(float(v) for v in state.position)
    pending_stop = True
    texts = [text for _, text in program.lines]
    file_line = np.array([number - 1 for number, _ in program.lines], dtype=int)
    rows = split_plain(texts)
    # index of the next line that is not plain (plain runs are read in bulk)
    other = np.flatnonzero([bool(r[5]) for r in rows]) if rows is not None else np.arange(len(texts))
    index = 0
    report = Stage(progress, "reading G-code", len(texts), "lines")
    written: dict[int, float] = {}
    idle = True  # GRBL Idle when the next line arrives: nothing queued since the last sync
    while index < len(texts):
        report.set(index)
        if rows is not None and not rows[index][5]:
            run_end = int(other[np.searchsorted(other, index)]) if len(other) and other[-1] >= index else len(texts)
            run = read_plain_run(rows[index:run_end], interp)
            if run is not None:
                cols.add_run(run, index, file_line[index:index + run.n], pending_stop, interp.state.spindle)
                max_s = max(max_s, float(run.s.max()))
                pending_stop = idle = False
                position = tuple(interp.state.position)
                index += run.n
                continue
        number, text = program.lines[index]
        index += 1
        if text.startswith("$"):
            answer = system_answer(text, settings, idle=idle) if allow_settings else None
            if answer is None or answer.code or answer.refused:
                # GRBL's own error where it names the fault; the refusal where the line would only
                # be refused for arriving mid-job (error:8), or not at all
                named = answer is not None and answer.refused and answer.code in (0, 8)
                why = SETTINGS_REFUSED if answer is None else f"it {answer.refused}; remove it from the job" \
                    if named else describe_error(answer.code)
                errors.append((number, f"{text}: {why}"))
                codes.append(answer.code if answer is not None and not named else 0)
            elif answer.setting is not None:
                settings[answer.setting[0]] = written[answer.setting[0]] = answer.setting[1]
                interp.config = replace(interp.config, laser_mode=bool(settings.get(32, 1)),
                                        arc_tolerance=settings.get(12, 0.002))
            elif answer.homes:
                interp.state.position = [0.0, 0.0, 0.0]
                position, pending_stop = (0.0, 0.0, 0.0), True
            continue
        try:
            actions = interp.execute(text)
        except GcodeError as error:
            errors.append((number, f"{text}: {describe_error(error.code)}"))
            codes.append(error.code)
            continue
        motion = interp.motion
        move_index = cols.n_moves()
        for action in actions:
            kind = action[0]
            if kind == "move":
                idle = False
                _, target, feed, rapid, mode, s = action
                cols.seg.append((position, target, np.nan if feed is None else feed, rapid, pending_stop,
                                 move_index, index - 1, mode != "M5" and s > 0 and not rapid))
                pending_stop = False
                position = target
                max_s = max(max_s, s)
            elif kind in ("sync", "end", "pause"):
                pending_stop = True
                idle = kind != "pause"  # M0 leaves GRBL in a feed hold
                syncs[index - 1] = True
            elif kind == "dwell":
                dwell[index - 1] += float(action[1])
                pending_stop = idle = True
            elif kind == "spindle":
                max_s = max(max_s, action[2])
        if motion is not None:
            st = interp.state
            on = st.spindle != "M5" and st.s > 0 and motion.kind != 0
            cols.mv.append((motion.kind, motion.start[:2], motion.end[:2],
                            motion.centre[:2] if motion.centre else (np.nan, np.nan),
                            np.nan if motion.kind == 0 else st.feed, st.s, on, number - 1))
    report.finish()
    (starts, ends, feeds, rapids, stops, seg_move, seg_index, seg_burn), moves = cols.arrays()
    seconds = plan_times(starts, ends, feeds, rapids, stops, kin)
    segments = Segments(starts, ends, feeds, rapids, stops, seg_move, seg_index, seconds)
    per_line = np.bincount(segments.index, weights=seconds, minlength=len(program)) + dwell
    points = np.vstack([np.asarray(start, dtype=float)[:2], ends[:, :2]])
    burn = np.vstack([starts[seg_burn, :2], ends[seg_burn, :2]])
    return ProgramStats(_box(points) if len(points) > 1 else None, _box(burn), max_s, bool(seg_burn.any()),
                        np.cumsum(per_line), tuple(errors), tuple(codes), moves, segments, dwell, syncs, written)
