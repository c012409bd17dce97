"""A drawing to a whole laser program: toolpath, G-code lines with their header, job time.

What `onestroke laser` and `onestroke batch` both write, made by one function so that the
two give the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass

from fabrication.laser.gcode_write import GcodeOptions, comment_line, gcode_parts, gcode_text
from fabrication.laser.toolpath import Toolpath, ToolpathOptions, plan_toolpath
from machines.gcode_program import ProgramStats
from machines.job_repeat import RepeatedLines, read_repeated
from machines.job_time import JobTime, format_duration
from onestroke.errors import OnestrokeError
from vectorize.drawing import Drawing


HEADER_LINES = 5  # comment lines before the G-code: name, size, settings, time, profile


@dataclass(frozen=True, kw_only=True, eq=False)
class LaserProgram:
    """toolpath: the planned burn (mm, machine frame); lines: the program without line
    endings, header comments first; time: `machines.job_time` estimate of `lines`; stats:
    `lines` as GRBL reads them (what the estimate and a preview use, read once); sent: the
    lines a sender streams (the header's comments are not sent)."""

    toolpath: Toolpath
    lines: tuple[str, ...]
    time: JobTime
    stats: ProgramStats
    sent: int

    @property
    def text(self) -> str:
        """The file content (`\\n` line endings)."""
        return gcode_text(list(self.lines))


def laser_program(drawing: Drawing, profile, toolpath_options: ToolpathOptions,
                  gcode_options: GcodeOptions, *, name: str, progress=None) -> LaserProgram:
    """Plan `drawing` for the laser `profile` and write its program; `name` (the input's file
    name) goes into the header comment. progress: an `onestroke.progress.ProgressCallback`
    (strokes planned, then G-code lines read back for the time estimate)."""
    toolpath = plan_toolpath(drawing, profile, toolpath_options, progress=progress)
    parts = gcode_parts(toolpath, profile, gcode_options, progress=progress)
    # machines/ reads the G-code as GRBL will, numbered as in the file: after the header's
    # comment lines, which GRBL never sees (so they change no time, only line numbers).
    # Passes repeat: it reads two of the repeated pair and extends (machines.job_repeat).
    head, body, count, tail = parts.repeated()
    reading = read_repeated(RepeatedLines(head=tuple(head), body=tuple(body), count=count, tail=tuple(tail),
                                          first_line=HEADER_LINES + 1), profile, allow_settings=False,
                            progress=progress)
    job = reading.time
    if job.errors:  # the writer's bug, not the user's input: say so before writing anything
        line, text = job.errors[0]
        raise OnestrokeError(f"internal error: GRBL would refuse generated line {line}: {text}")
    w, h = toolpath.size
    power = gcode_options.power
    comments = (
        f"onestroke laser: {name}",
        f"{w:.1f} x {h:.1f} mm, {len(toolpath.paths)} stroke(s), {gcode_options.passes} pass(es)",
        f"feed {gcode_options.feed:g} mm/min, power {power * 100:g}% (S{power * profile.max_power:g})",
        f"estimated time {format_duration(job.total_seconds)} ({job.bound_text(profile)})",
        f"profile: {profile.name}",
    )
    return LaserProgram(toolpath=toolpath, lines=tuple(comment_line(c) for c in comments) + tuple(parts.lines()),
                        time=job, stats=reading.stats, sent=reading.sent)
