"""G-code for GRBL 1.1 in laser mode, written from a planned `Toolpath`.

Program shape (see docs/laser.md): comment lines, `G21`, `G90`, `M4S0` once (dynamic power:
the beam scales with speed and is off when still), `M8` if air assist; per stroke a `G0` to
its start, then `G1`/`G2`/`G3` moves with `S` and `F` on the first (the motion word only
where it changes: it is modal); `M5`, `M9` at the end,
then an optional `G0X0Y0`. No M3/M4/M5/M8 between strokes: each of them makes GRBL drain
its planner to a full stop. Numbers carry at most 3 decimals without trailing zeros, words
are not separated by spaces (they waste GRBL's 128-byte receive buffer), lines end in `\\n`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from fabrication.laser.arcs import LINE
from fabrication.laser.toolpath import BurnPath, Toolpath
from machines.laser_profile import LaserProfile
from onestroke.atomic import atomic_write_text
from onestroke.progress import ProgressCallback, Stage
from onestroke.ranges import Range, check_ranges, ranged

# Burn speed: under 1 mm/min the file would say F0, which GRBL refuses.
FEED = Range(1.0, 100_000.0, unit="mm/min", name="--feed")
# A fraction of the profile's max S ($30), shown in percent.
POWER = Range(0.0, 1.0, unit="%", name="--power", low_open=True, scale=100.0)
# Each pass repeats the whole program: passes bound the file's size and the job's time.
PASSES = Range(1, 100, name="--passes", integer=True)

MAX_LINE = 80  # GRBL's line buffer; longer lines get error:11


@dataclass(frozen=True, kw_only=True)
class GcodeOptions:
    """feed: burn speed, mm/min. power: fraction (0..1] of the profile's max S ($30).
    passes: times the job is burned; even passes run the job backwards so each pass starts
    where the last ended. return_home: end with G0X0Y0. air_assist: None uses the
    profile's setting. dynamic: M4 (True, even burn through corners) or M3 constant power.
    """

    feed: float = ranged(1500.0, FEED)
    power: float = ranged(0.6, POWER)
    passes: int = ranged(1, PASSES)
    return_home: bool = False
    air_assist: bool | None = None
    dynamic: bool = True

    def __post_init__(self) -> None:
        check_ranges(self)


def comment_line(text: str) -> str:
    """A `;` comment line: ASCII only, one line, at most 80 characters."""
    clean = " ".join(text.split()).encode("ascii", "replace").decode("ascii")
    return ("; " + clean)[:MAX_LINE].rstrip()


def fmt(value: float) -> str:
    """A compact G-code number: 3 decimals at most, no trailing zeros, no '-0'."""
    text = ("%.3f" % value).rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _fmt_many(values: np.ndarray) -> list[str]:
    out = [("%.3f" % v).rstrip("0").rstrip(".") for v in values.tolist()]
    return ["0" if s == "-0" else s for s in out] if "-0" in out else out


def _path_lines(path: BurnPath, position: tuple[str, str], first_words: str) -> tuple[list[str], tuple[str, str]]:
    """Lines that move from `position` (formatted x, y) to the path and burn it."""
    xs, ys = _fmt_many(path.points[:, 0]), _fmt_many(path.points[:, 1])
    lines = []
    px, py = position
    if (xs[0], ys[0]) != (px, py):
        lines.append("G0" + ("X" + xs[0] if xs[0] != px else "") + ("Y" + ys[0] if ys[0] != py else ""))
    arc = path.kinds != LINE
    if arc.any():
        offsets = path.centres - path.points[:-1]
        i_words, j_words = _fmt_many(np.nan_to_num(offsets[:, 0])), _fmt_many(np.nan_to_num(offsets[:, 1]))
    kinds = path.kinds.tolist()
    mode = 0
    for k in range(len(kinds)):
        x, y, kind = xs[k + 1], ys[k + 1], kinds[k]
        # the motion word is modal in GRBL: written only when it changes, which saves 2 of
        # ~16 bytes a line on the serial link, the limit on dense jobs
        words = "G%d" % kind if kind != mode else ""
        mode = kind
        # an axis word is left out when its value does not change (also modal)
        if x != xs[k]:
            words += "X" + x
        if y != ys[k]:
            words += "Y" + y
        if kind != LINE:
            # GRBL needs at least one of I, J; zero offsets are left out
            if i_words[k] != "0":
                words += "I" + i_words[k]
            if j_words[k] != "0" or i_words[k] == "0":
                words += "J" + j_words[k]
        if k == 0:
            words += first_words
        lines.append(words)
    return lines, (xs[-1], ys[-1])


@dataclass(frozen=True)
class GcodeParts:
    """A program as written: head (units, mode, beam), one list of lines per pass, tail
    (beam off, home). Passes that start from the same place in the same direction are the
    same list object: pass k + 2 repeats pass k from the third pass on."""

    head: list[str]
    passes: list[list[str]]
    tail: list[str]

    def lines(self) -> list[str]:
        """Every line, in order."""
        out = list(self.head)
        for lines in self.passes:
            out.extend(lines)
        return out + self.tail

    def repeated(self) -> tuple[list[str], list[str], int, list[str]]:
        """(head, body, count, tail) with `lines()` == head + body x count + tail: the body is
        the longest run of passes that repeats as a pair (one forward, one backward)."""
        passes = self.passes
        first = 1  # the first pass starts from an unknown place (its G0): never repeated
        if not all(passes[k] is passes[k - 2] for k in range(first + 2, len(passes))):
            first = len(passes)
        count = (len(passes) - first) // 2
        head = list(self.head)
        for lines in passes[:first]:
            head.extend(lines)
        body = passes[first] + passes[first + 1] if count else []
        tail = [line for lines in passes[first + 2 * count:] for line in lines] + self.tail
        return head, body, count, tail


def gcode_parts(toolpath: Toolpath, profile: LaserProfile, options: GcodeOptions = GcodeOptions(), *,
                comments: tuple[str, ...] = (), progress: ProgressCallback | None = None) -> GcodeParts:
    """The program (`gcode_lines`) in its parts. progress: an
    `onestroke.progress.ProgressCallback` (strokes written, over all passes)."""
    air = profile.air_assist if options.air_assist is None else options.air_assist
    s_value = fmt(options.power * profile.max_power)
    first_words = f"S{s_value}F{fmt(options.feed)}"
    head = [comment_line(c) for c in comments]
    head += ["G21", "G90", "M4S0" if options.dynamic else "M3S0"]
    if air:
        head.append("M8")
    # the head's position is unknown before the job: the first stroke always gets its G0
    position = ("", "")
    report = Stage(progress, "writing G-code", options.passes * len(toolpath.paths), "strokes")
    # a pass is a function of its direction and where the head starts: written once each
    written: dict[tuple[int, tuple[str, str]], tuple[list[str], tuple[str, str]]] = {}
    passes = []
    for index in range(options.passes):
        key = (index % 2, position)
        if key not in written:
            paths = toolpath.paths if index % 2 == 0 else tuple(p.reversed() for p in toolpath.paths[::-1])
            lines, end = [], position
            for path in paths:
                more, end = _path_lines(path, end, first_words)
                lines.extend(more)
            written[key] = (lines, end)
        lines, position = written[key]
        passes.append(lines)
        report.advance(len(toolpath.paths))
    report.finish()
    tail = ["M5", "M9"]
    if options.return_home and position != ("0", "0"):
        tail.append("G0X0Y0")
    return GcodeParts(head, passes, tail)


def gcode_lines(toolpath: Toolpath, profile: LaserProfile, options: GcodeOptions = GcodeOptions(), *,
                comments: tuple[str, ...] = (), progress: ProgressCallback | None = None) -> list[str]:
    """The whole program as lines without line endings (each <= 80 characters).
    progress: an `onestroke.progress.ProgressCallback` (strokes written, over all passes)."""
    return gcode_parts(toolpath, profile, options, comments=comments, progress=progress).lines()


def gcode_text(lines: list[str]) -> str:
    """Lines joined with `\\n` endings (never `\\r\\n`: GRBL would answer twice)."""
    return "\n".join(lines) + "\n"


def write_gcode(path: str | os.PathLike, lines: list[str]) -> None:
    """Write the program atomically."""
    atomic_write_text(path, gcode_text(lines))
