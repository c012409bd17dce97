"""A job whose middle repeats (a laser's passes): read and time two periods, prove that the
rest repeat, and extend the result, instead of reading every period.

A job `head + body x count + tail` (lines) is read as `head + body x 2 + tail` by the same
`analyze_program` and `link_schedule` as any program. Everything that happens after a point
of the job depends on the lines after it and on a bounded state before it: in the planner
model, the squared speed leaving the last block (`plan_times`); in the link model, the
answers and arrivals of the lines still in GRBL's RX buffer, the end times and exit speeds of
the last `planner_blocks` blocks (`LinkSchedule`), and the blocks' own limits (`block_table`,
which include the corner with the block before). When that state at the start of the second
period is the state at the start of the first shifted by a time D, with the same block
limits in both periods, the periods 2 .. count - 1 are the first one shifted by D, 2D, ...
(each is followed by a body, as the first is in the two-period reading), and the last period
and the tail are the two-period reading's shifted by (count - 2) D. Where the check fails (a
short body, a job whose state settles only later) the whole job is read: the result is then
the same as `analyze_program` + `estimate_program_time` of all its lines by construction.

Exactness: values equal to float rounding (checked within `TIME_TOLERANCE` seconds per
period, so the total is within count x that of the full reading), except where the model
itself branches on two equal times (a block planned just as the one before ends), where a
rounding difference could take the other branch; tests compare with the full reading to the
millisecond (tests/laser/test_passes.py).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from machines.gcode_program import GcodeMoves, Program, ProgramStats, Segments, analyze_program, program_from_lines
from machines.grbl_settings import settings_from_profile
from machines.job_time import JobTime, estimate_program_time, job_time_of, link_schedule, profile_kinematics
from machines.laser_profile import LaserProfile
from machines.planner_model import block_table, plan_times
from onestroke.progress import ProgressCallback

# Two periods' boundary states agree when their times differ by D within this (s), speeds
# within this (mm/s, (mm/s)^2): float rounding is ~1e-12 s on hours-long jobs.
TIME_TOLERANCE = 1e-6
# The period (1-based) whose start state is compared with the next one's: the first; where
# the start's transient (an empty planner, the first G0) has not died out by then, the third,
# then the seventh (each a reading of one period more than that).
SETTLED = (1, 3, 7)


@dataclass(frozen=True, kw_only=True)
class RepeatedLines:
    """G-code lines `head + body x count + tail` (str, no line ends); first_line: the file
    line number of head[0] (lines before it, such as header comments, are not sent)."""

    head: tuple[str, ...]
    body: tuple[str, ...]
    count: int
    tail: tuple[str, ...]
    first_line: int = 1

    def lines(self) -> list[str]:
        """Every line, in order."""
        return list(self.head) + list(self.body) * self.count + list(self.tail)

    def program(self, count: int | None = None) -> Program:
        """The lines as GRBL reads them, numbered as in the file, with `count` bodies
        (default: all)."""
        copies = self.count if count is None else count
        body = program_from_lines(list(self.head) + list(self.body) * copies + list(self.tail))
        shift = self.first_line - 1
        return Program(body.source, tuple((n + shift, text) for n, text in body.lines), body.n_lines + shift)


@dataclass(frozen=True, kw_only=True)
class RepeatedReading:
    """stats, time: the whole job's `ProgramStats` and `JobTime`, as if all its lines were
    read; sent: the lines GRBL receives; extended: whether two periods were read and the
    rest extended (False: every line was read)."""

    stats: ProgramStats
    time: JobTime
    sent: int
    extended: bool


def read_repeated(job: RepeatedLines, profile: LaserProfile, *, allow_settings: bool = False,
                  progress: ProgressCallback | None = None) -> RepeatedReading:
    """The reading and job-time estimate of `job` on `profile` (see the module doc);
    `allow_settings`, `progress` as in `analyze_program`."""
    settings = settings_from_profile(profile)
    for period in SETTLED:
        if not job.body or job.count <= period + 1:
            break
        program = job.program(period + 1)
        stats = analyze_program(program, settings=settings, planner_blocks=profile.planner_blocks,
                                allow_settings=allow_settings, progress=progress)
        extended = _extend(job, program, stats, profile, period)
        if extended is not None:
            return extended
        progress = None  # the reading was reported once
    program = job.program()
    stats = analyze_program(program, settings=settings, planner_blocks=profile.planner_blocks,
                            allow_settings=allow_settings, progress=progress)
    return RepeatedReading(stats=stats, time=estimate_program_time(program, profile, stats=stats),
                           sent=len(program), extended=False)


def _tiled(x: np.ndarray, cut: tuple[int, int, int], copies: int, shift=0) -> np.ndarray:
    """x over [prefix | P1 | P2 | rest] (P1 = x[a:b], P2 = x[b:c], cut = (a, b, c)) -> the
    same over `copies` periods: [prefix | P1 | P1 + shift | ... | P1 + (copies - 2) shift |
    P2 + (copies - 2) shift | rest + (copies - 2) shift]."""
    a, b, _ = cut
    extra = copies - 2
    if not shift:
        return np.concatenate([x[:b], np.tile(x[a:b], (extra,) + (1,) * (x.ndim - 1)), x[b:]])
    steps = np.arange(1, extra + 1).reshape((-1,) + (1,) * x.ndim)
    middle = (x[a:b][None] + steps * shift).reshape((-1,) + x.shape[1:])
    return np.concatenate([x[:b], middle, x[b:] + extra * shift])


def _same(first: np.ndarray, second: np.ndarray, shift: float = 0.0, *, exact: bool = False) -> bool:
    if first.shape != second.shape:
        return False
    if exact:
        return bool(np.array_equal(first, second))
    return bool(np.all(np.abs(second - first - shift) <= TIME_TOLERANCE))


def _extend(job: RepeatedLines, program: Program, stats: ProgramStats, profile: LaserProfile,
            period: int) -> RepeatedReading | None:
    """The whole job from the reading of its first `period` + 1 periods, or None when the
    states at the starts of the last two differ."""
    kin = profile_kinematics(profile)
    numbers = np.fromiter((n - 1 for n, _ in program.lines), dtype=int, count=len(program))
    # program lines (index) where the compared periods start, and file lines (0-based) per body
    span = len(job.body)
    first_file = job.first_line - 1 + len(job.head) + (period - 1) * span
    lines_cut = tuple(int(v) for v in np.searchsorted(numbers, [first_file, first_file + span, first_file + 2 * span]))
    seg, moves = stats.segments, stats.moves
    seg_cut = tuple(int(v) for v in np.searchsorted(seg.index, lines_cut))
    move_cut = tuple(int(v) for v in np.searchsorted(moves.line, [first_file, first_file + span, first_file + 2 * span]))
    a, b, c = lines_cut
    sa, sb, sc = seg_cut
    if not (0 < a < b < c) or b - a != c - b or sb - sa != sc - sb:
        return None
    schedule = link_schedule(program, stats, kin, baud=profile.baud, rx_buffer=profile.rx_buffer,
                             parse_time=profile.parse_time)
    # the blocks' own limits (corners with the block before included) are the same in both periods
    table = block_table(seg.start, seg.end, seg.feed, seg.rapid, seg.stop_before, kin)
    kept = np.flatnonzero(table.keep)
    ka, kb, kc = (int(v) for v in np.searchsorted(kept, seg_cut))
    window = kin.planner_blocks
    if kb - ka < window or ka < window:
        return None
    limits = (table.length, table.accel, table.nominal, table.max_entry, table.reach)
    if not all(_same(x[ka:kb], x[kb:kc], exact=True) for x in limits):
        return None
    if not np.array_equal(schedule.head[a:b] - a, schedule.head[b:c] - b):
        return None
    # the link's state at each period's start: lines in flight, the last `window` blocks
    back = b - int(schedule.head[b]) + 1
    if back > b - a or a - back < 0:
        return None
    shift = float(schedule.ack[b - 1] - schedule.ack[a - 1])
    line_state = [(schedule.ack, shift), (schedule.arrived, shift)]
    ends, speeds = schedule.block_end[kept], schedule.exit_speed[kept]
    if not all(_same(x[a - back:a], x[b - back:b], d) for x, d in line_state):
        return None
    if not (_same(ends[ka - window:ka], ends[kb - window:kb], shift)
            and _same(speeds[ka - window:ka], speeds[kb - window:kb])):
        return None
    # the planner model's state: the squared speed leaving the block before each period
    _, leaving = plan_times(seg.start, seg.end, seg.feed, seg.rapid, seg.stop_before, kin, exits=True)
    leaving = leaving[kept]
    if not _same(leaving[ka - 1:ka], leaving[kb - 1:kb]):
        return None

    copies = job.count - (period - 1)  # periods from the first compared one on
    planner_shift = float(stats.line_seconds[b - 1] - stats.line_seconds[a - 1])
    full_stats = _tiled_stats(stats, lines_cut, seg_cut, move_cut, copies, first_file, span, planner_shift)
    block_end = _tiled(schedule.block_end, seg_cut, copies, shift)
    block_end[_tiled(schedule.block_end, seg_cut, copies) == 0.0] = 0.0  # zero-step segments never run
    n_lines = program.n_lines + (copies - 2) * span
    time = job_time_of(full_stats, profile, numbers=_tiled(numbers, lines_cut, copies, span), n_lines=n_lines,
                       ack=_tiled(schedule.ack, lines_cut, copies, shift), block_end=block_end)
    return RepeatedReading(stats=full_stats, time=time, sent=len(program) + (copies - 2) * (b - a), extended=True)


def _tiled_stats(stats: ProgramStats, lines_cut, seg_cut, move_cut, copies: int, first_file: int, span: int,
                 planner_shift: float) -> ProgramStats:
    """`ProgramStats` of the whole job from the two-period reading's; first_file: 0-based
    file line where the first period starts, span: file lines per period."""
    seg, moves = stats.segments, stats.moves
    a, b, _ = lines_cut
    period_lines, period_moves = b - a, move_cut[1] - move_cut[0]
    segments = Segments(*(_tiled(x, seg_cut, copies) for x in (seg.start, seg.end, seg.feed, seg.rapid,
                                                                  seg.stop_before)),
                        move=_tiled(seg.move, seg_cut, copies, period_moves),
                        index=_tiled(seg.index, seg_cut, copies, period_lines),
                        seconds=_tiled(seg.seconds, seg_cut, copies))
    gcode_moves = GcodeMoves(*(_tiled(x, move_cut, copies) for x in (moves.kind, moves.start, moves.end, moves.centre,
                                                                      moves.feed, moves.power, moves.laser_on)),
                             line=_tiled(moves.line, move_cut, copies, span))
    # refused lines repeat with their period (none in a job onestroke writes)
    errors, codes = [], []
    for (number, text), code in zip(stats.errors, stats.codes):
        line = number - 1 - first_file  # 0-based, from the first period's start
        offsets = range(0, (copies - 1) * span, span) if 0 <= line < span else \
            [(copies - 2) * span] if line >= span else [0]
        errors += [(number + k, text) for k in offsets]
        codes += [code] * len(offsets)
    return replace(stats, line_seconds=_tiled(stats.line_seconds, lines_cut, copies, planner_shift),
                   errors=tuple(errors), codes=tuple(codes), moves=gcode_moves, segments=segments,
                   dwell=_tiled(stats.dwell, lines_cut, copies), syncs=_tiled(stats.syncs, lines_cut, copies))

