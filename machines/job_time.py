"""How long a G-code job takes on a GRBL 1.1h laser: the one job-time estimate of onestroke.

Two bounds, both modelled:
- the planner: GRBL's motion planner run over the whole program (`planner_model.plan_times`,
  the same core the emulator runs block by block);
- the link and the parser: a character-counting sender at the profile's baud rate into
  GRBL's RX buffer (`rx_buffer`, 128 bytes), and `parse_time` per line on the controller
  (2 ms for an ATmega328). A line is parsed once its last byte arrived and the previous
  line is done; it needs a free planner block (one of `planner_blocks`) for each move,
  and its `ok` frees its bytes in the sender's count. Blocks run in order, each as soon
  as it is planned and the previous one has finished, planned with the look-ahead of
  the blocks in the planner by then (a starved planner slows the machine down).
Dense jobs of very short moves (0.05-0.1 mm at high feed) are bound by the link and the
parser; everything else by the planner. `JobTime.bound` says which.

Public API: `estimate_job_time(lines, profile)` and `estimate_program_time(program,
profile)` -> `JobTime` (with per-line and per-block seconds for progress and players).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from machines.gcode_program import GcodeMoves, Program, ProgramStats, analyze_program, program_from_lines
from machines.grbl_settings import settings_from_profile
from machines.laser_profile import LaserProfile
from machines.planner_model import Kinematics, block_table, trapezoid, window_limits
from onestroke.progress import ProgressCallback

# A USB-serial adapter delivers a burst about half a millisecond after it was written
# (about 1 ms for a round trip, grbl.md); the emulator uses the same figure.
USB_LATENCY = 0.0005
BITS_PER_BYTE = 10  # 8-N-1: start bit, 8 data bits, stop bit
OK_BYTES = 4  # "ok\r\n"


@dataclass(frozen=True, kw_only=True)
class JobTime:
    """Seconds a job takes on GRBL, with the break-down.

    total_seconds: the job, the slower of the two bounds interleaved line by line.
    planner_seconds: the job if lines arrived instantly (planner-limited).
    link_seconds: time for the last line to be sent, parsed and acknowledged.
    bound: "planner" or "link" - which one sets the pace (link: total more than 2 %
    above the planner figure). line_seconds (n_lines,): cumulative seconds at the end of
    each source line (for an ETA while streaming). block_seconds (B,): each planner
    block's seconds (planner-limited); block_line (B,) its 0-based source line.
    burn_seconds / travel_seconds: planner seconds of motion with the beam able to fire
    (M3/M4, S > 0, not G0) and of the rest; burn_length / travel_length: mm.
    naive_seconds: length / feed, what common senders show. blocks: planner blocks.
    errors: (file line, text) of lines GRBL would refuse (see `analyze_program`).
    """

    total_seconds: float
    planner_seconds: float
    link_seconds: float
    bound: str
    line_seconds: np.ndarray
    block_seconds: np.ndarray
    block_line: np.ndarray
    burn_seconds: float
    travel_seconds: float
    burn_length: float
    travel_length: float
    naive_seconds: float
    blocks: int
    errors: tuple[tuple[int, str], ...] = ()

    def bound_text(self, profile: LaserProfile) -> str:
        """One phrase saying which bound sets the job's pace."""
        if self.bound == "link":
            return (f"bound by the serial link and parser ({profile.baud} baud, {profile.parse_time * 1000:g} ms a "
                    f"line; the planner alone: {format_duration(self.planner_seconds)})")
        return "bound by GRBL's planner"


@dataclass(frozen=True)
class LinkSchedule:
    """A job streamed by character counting, in seconds from the first byte sent.

    Per program line (n,): ack (its `ok` is back), arrived (its last byte reached the
    controller), head (the line the sender waited for before sending it: line i goes out
    once line head[i] - 1 is answered). Per segment (B,): block_end (it finished moving),
    planned (it entered the planner), exit_speed (mm/s, leaving it); 0 for segments of
    zero steps. Everything a line or block after a point reads of the lines and blocks
    before it is among these (see `machines.job_repeat`).
    """

    ack: np.ndarray
    arrived: np.ndarray
    head: np.ndarray
    block_end: np.ndarray
    planned: np.ndarray
    exit_speed: np.ndarray


def link_schedule(program: Program, stats: ProgramStats, kin: Kinematics, *, baud: int, rx_buffer: int,
                  parse_time: float, latency: float = USB_LATENCY) -> LinkSchedule:
    """When each line is acknowledged and each block ends, streamed by character counting.

    Two interleaved passes: the parser side (each line's arrival over the wire, its parse,
    a free planner block for each of its moves) and the motion side (each block runs when
    the previous one ended and it is planned, with the look-ahead of the blocks planned
    by then: a starved planner must be able to stop after its last block, as GRBL's).
    """
    byte_time = BITS_PER_BYTE / float(baud)
    ok_time = latency + OK_BYTES * byte_time
    seg = stats.segments
    n = len(program)
    sizes = np.fromiter((len(text) + 1 for _, text in program.lines), dtype=np.int64, count=n)
    total = np.concatenate([[0], np.cumsum(sizes)])
    # character counting: line i goes out once every line before `head[i]` is answered,
    # the first one from which the unanswered bytes plus line i fit the RX buffer (the
    # answers come in order, so waiting for the newest of them is waiting for all)
    heads = np.minimum(np.searchsorted(total, total[1:] - rx_buffer, side="left"), np.arange(n))
    head = heads.tolist()
    wire = (sizes * byte_time).tolist()
    table = block_table(seg.start, seg.end, seg.feed, seg.rapid, seg.stop_before, kin)
    moving = np.flatnonzero(table.keep)
    lines_of = seg.index[moving]
    first = np.searchsorted(lines_of, np.arange(n), side="left").tolist()
    last = np.searchsorted(lines_of, np.arange(n), side="right").tolist()
    syncs, dwell = stats.syncs.tolist(), stats.dwell.tolist()
    blocks = len(moving)
    window = kin.planner_blocks
    planned = [math.inf] * blocks  # when each block entered the planner
    ends = [0.0] * blocks  # when each block finished moving
    ack = [0.0] * n
    arrival = [0.0] * n
    exits = [0.0] * blocks
    done_blocks = [0]  # how many blocks have their end time

    def parser_side():
        # yields whenever it needs the end of a block the motion side has not reached
        wire_free = 0.0  # when the host's last byte has arrived at the controller
        parser_free = 0.0
        for i in range(n):
            h = head[i]
            send = ack[h - 1] if h else 0.0
            # (comparisons instead of max(): the same values, this loop runs once per line)
            arrived = send + latency
            if arrived < wire_free:
                arrived = wire_free
            arrived += wire[i]
            wire_free = arrival[i] = arrived
            done = (arrived if arrived >= parser_free else parser_free) + parse_time
            if syncs[i]:  # M3/M4/M5, M8/M9, G4, S without motion: the planner drains first
                while done_blocks[0] < first[i]:
                    yield
                done = max(done, ends[first[i] - 1] if first[i] else 0.0) + dwell[i]
            for b in range(first[i], last[i]):
                if b >= window:  # a free planner block: the one `window` back has run
                    while done_blocks[0] <= b - window:
                        yield
                    if ends[b - window] > done:
                        done = ends[b - window]
                planned[b] = done
            parser_free = done
            ack[i] = done + ok_time

    parser = parser_side()
    length, accel, nominal = table.length.tolist(), table.accel.tolist(), table.nominal.tolist()
    max_entry, reach = table.max_entry.tolist(), table.reach.tolist()
    full = window_limits(table, window).tolist()  # exit limits with a full planner
    v, previous_end = 0.0, 0.0
    for b in range(blocks):
        next(parser, None)  # plans every block it can before block b ends
        start = max(previous_end, planned[b])
        if planned[b] > previous_end or max_entry[b] == 0.0:
            v = 0.0  # the planner ran dry (or a forced stop): from rest
        top = min(b + window, blocks)
        if planned[top - 1] <= start:  # the whole look-ahead is planned: the batch's limit
            profile = trapezoid(v, math.sqrt(full[b]), nominal[b], accel[b], length[b])
        else:
            seen = bisect.bisect_right(planned, start, b, top)
            profile = _block_profile(b, seen, v, length, accel, nominal, max_entry, reach)
            more = bisect.bisect_right(planned, start + profile.duration, b, top)
            if more > seen:  # blocks planned while this one runs raise its exit speed (GRBL re-plans)
                profile = _block_profile(b, more, v, length, accel, nominal, max_entry, reach)
        previous_end = ends[b] = start + profile.duration
        v = exits[b] = profile.v_exit
        done_blocks[0] = b + 1
    for _ in parser:  # lines after the last block (and any left if there are no blocks)
        pass
    block_end, entered, exit_speed = np.zeros(len(seg)), np.zeros(len(seg)), np.zeros(len(seg))
    block_end[moving], entered[moving], exit_speed[moving] = ends, planned, exits
    return LinkSchedule(ack=np.array(ack), arrived=np.array(arrival), head=heads, block_end=block_end,
                        planned=entered, exit_speed=exit_speed)


def _block_profile(b: int, seen: int, v0: float, length, accel, nominal, max_entry, reach):
    """Trapezoid of block b entered at v0, with blocks b..seen-1 in the planner (the last
    of them must be able to stop)."""
    limit = 0.0
    for k in range(seen - 1, b, -1):
        limit = min(max_entry[k], limit + reach[k])
    return trapezoid(v0, math.sqrt(limit), nominal[b], accel[b], length[b])


def estimate_program_time(program: Program, profile: LaserProfile, *, stats: ProgramStats | None = None,
                          link: bool = True, allow_settings: bool = False,
                          progress: ProgressCallback | None = None) -> JobTime:
    """`JobTime` of `program` on the machine `profile` describes (see the module doc).

    link: False models the planner alone (lines arrive instantly). allow_settings: see
    `analyze_program` (False: `$` lines are reported in `errors`). progress: an
    `onestroke.progress.ProgressCallback` (lines read), when `stats` is not given.
    """
    if stats is None:
        stats = analyze_program(program, settings=settings_from_profile(profile),
                                planner_blocks=profile.planner_blocks, allow_settings=allow_settings,
                                progress=progress)
    schedule = None
    if link and len(program):
        schedule = link_schedule(program, stats, profile_kinematics(profile), baud=profile.baud,
                                 rx_buffer=profile.rx_buffer, parse_time=profile.parse_time)
    numbers = np.fromiter((n - 1 for n, _ in program.lines), dtype=int, count=len(program))
    n_lines = max(program.n_lines, max((n for n, _ in program.lines), default=0))
    return job_time_of(stats, profile, numbers=numbers, n_lines=n_lines,
                       ack=None if schedule is None else schedule.ack,
                       block_end=None if schedule is None else schedule.block_end)


def profile_kinematics(profile: LaserProfile) -> Kinematics:
    """The planner model's limits of the machine `profile` describes."""
    return Kinematics.from_settings(settings_from_profile(profile), planner_blocks=profile.planner_blocks)


def job_time_of(stats: ProgramStats, profile: LaserProfile, *, numbers: np.ndarray, n_lines: int,
                ack: np.ndarray | None, block_end: np.ndarray | None) -> JobTime:
    """`JobTime` from a program's reading and its link schedule (None: the planner alone).

    numbers (len(program),): 0-based file line of each program line; n_lines: lines in the
    file; ack (len(program),), block_end (B,): `LinkSchedule.ack`, `.block_end`.
    """
    seg, moves = stats.segments, stats.moves
    seconds = seg.seconds
    planner = stats.total_seconds
    if ack is not None:
        link_total = float(ack[-1])
        total = max(float(block_end.max()) if len(block_end) else 0.0, link_total, planner)
        line_done = np.maximum(ack, np.maximum.accumulate(_line_ends(stats, block_end, len(ack))))
    else:
        link_total, total = 0.0, planner
        line_done = stats.line_seconds
    line_seconds = np.zeros(n_lines)
    if len(numbers):
        line_seconds[numbers] = line_done
        line_seconds = np.maximum.accumulate(line_seconds)
    chord = np.linalg.norm(seg.end - seg.start, axis=1) if len(seg) else np.zeros(0)
    burn_seg = moves.laser_on[seg.move] if len(seg) and len(moves) else np.zeros(len(seg), dtype=bool)
    feed = np.where(seg.rapid, profile.rapid_rate, np.nan_to_num(seg.feed, nan=profile.rapid_rate))
    naive = float((chord / np.maximum(feed, 1e-9)).sum() * 60.0 + stats.dwell.sum())
    return JobTime(
        total_seconds=total, planner_seconds=planner, link_seconds=link_total,
        bound="link" if total > planner * 1.02 + 1e-9 else "planner", line_seconds=line_seconds,
        block_seconds=seconds, block_line=numbers[seg.index] if len(seg) else np.zeros(0, dtype=int),
        burn_seconds=float(seconds[burn_seg].sum()), travel_seconds=float(seconds[~burn_seg].sum()),
        burn_length=float(chord[burn_seg].sum()), travel_length=float(chord[~burn_seg].sum()),
        naive_seconds=naive, blocks=int((seconds > 0).sum()), errors=stats.errors)


def _line_ends(stats: ProgramStats, block_end: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros(n)
    if len(block_end):
        np.maximum.at(out, stats.segments.index, block_end)
    return out


def estimate_job_time(lines: Sequence[str], profile: LaserProfile, *, link: bool = True,
                      progress: ProgressCallback | None = None) -> JobTime:
    """`JobTime` of G-code given as lines (str, without line ends); `progress` as in
    `estimate_program_time`."""
    return estimate_program_time(program_from_lines(lines), profile, link=link, progress=progress)


def read_moves(lines: Sequence[str], profile: LaserProfile) -> tuple[GcodeMoves, ProgramStats]:
    """Every motion command of `lines` as GRBL reads it (for previews and checks)."""
    program = program_from_lines(lines)
    stats = analyze_program(program, settings=settings_from_profile(profile), planner_blocks=profile.planner_blocks)
    return stats.moves, stats


def format_duration(seconds: float) -> str:
    """'1:02:03', '2:05' or '12.3 s'."""
    if seconds < 60:
        return f"{seconds:.1f} s"
    whole = int(round(seconds))
    h, rest = divmod(whole, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"
