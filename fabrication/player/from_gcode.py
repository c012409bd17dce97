"""Player rows from a G-code program, timed by `machines.job_time` (GRBL's model).

Each move becomes the chords GRBL cuts it into (arcs: `$12` chords; lines: one row), as
`machines.gcode_program` reads them. Times come from the estimate's cumulative time per
source line, so the player's clock ends on the job-time estimate; within a line the time
is shared along the chords by length.
"""

from __future__ import annotations

import os

import numpy as np

from fabrication.laser.preview import order_colours
from fabrication.player.data import DRAW, TRAVEL, PlayerData, ramp_palette
from machines.gcode_program import analyze_program, load_program, program_from_lines
from machines.grbl_settings import settings_from_profile
from machines.job_time import estimate_program_time, format_duration
from machines.laser_profile import LaserProfile, load_laser_profile
from onestroke.errors import InputError


def gcode_player_data(lines, *, title: str = "G-code",
                      profile: LaserProfile | None = None) -> PlayerData:
    """`PlayerData` of G-code `lines` (str, with or without endings), in machine mm (+y up).

    profile: the machine (time model, bed outline); None uses the default profile. Burn
    moves are coloured along the job's order like the PNG preview; travel is TRAVEL.
    """
    program = program_from_lines([text.rstrip("\r\n") for text in lines], source=title)
    return _player_data(program, title, profile)


def laser_program_player_data(program, *, title: str, profile: LaserProfile) -> PlayerData:
    """`PlayerData` of a `fabrication.laser.program.LaserProgram` made for `profile`: the
    same as `gcode_player_data(program.lines)`, from the reading its estimate made."""
    return _timed_player_data(program.stats, program.time, title, profile)


def _player_data(program, title: str, profile: LaserProfile | None) -> PlayerData:
    profile = profile or load_laser_profile()
    stats = analyze_program(program, settings=settings_from_profile(profile), planner_blocks=profile.planner_blocks)
    if len(stats.moves) == 0 or len(stats.segments) == 0:
        raise InputError(f"G-code {title!r} holds no moves to play")
    return _timed_player_data(stats, estimate_program_time(program, profile, stats=stats), title, profile)


def _timed_player_data(stats, job, title: str, profile: LaserProfile) -> PlayerData:
    moves, seg = stats.moves, stats.segments
    if len(moves) == 0 or len(seg) == 0:
        raise InputError(f"G-code {title!r} holds no moves to play")
    n_lines = len(job.line_seconds)
    segments = np.stack([seg.start[:, :2], seg.end[:, :2]], axis=1)
    owner = seg.move
    line = job.block_line
    chord = np.hypot(*(segments[:, 1] - segments[:, 0]).T)

    # chords of one line share that line's planner time by length (equally if all are 0)
    line_end = job.line_seconds
    line_start = np.r_[0.0, line_end[:-1]]
    first = np.r_[True, line[1:] != line[:-1]]
    group = np.cumsum(first) - 1
    weight = np.where(np.bincount(group, weights=chord)[group] > 0, chord, 1.0)
    done = np.cumsum(weight)
    before = (done - weight)[first][group]
    share = (done - before) / np.bincount(group, weights=weight)[group]
    times = line_start[line] + (line_end[line] - line_start[line]) * share

    burn = moves.laser_on[owner]
    along = np.cumsum(np.where(burn, chord, 0.0))
    fraction = along / along[-1] if along[-1] > 0 else np.zeros(len(along))
    colors, palette = ramp_palette(fraction, order_colours)
    # row 0 is where the head starts (the first move's start), then one row per chord
    points = np.vstack([segments[:1, 0], segments[:, 1]])
    kinds = np.r_[TRAVEL, np.where(burn, DRAW, TRAVEL)].astype(np.uint8)
    info = (f"time {format_duration(job.total_seconds)} ({'serial link' if job.bound == 'link' else 'planner'} bound)",
            f"length / feed {format_duration(job.naive_seconds)}",
            f"burn {job.burn_length:.0f} mm, travel {job.travel_length:.0f} mm",
            f"{n_lines} lines, {job.blocks} planner blocks",
            f"bed {profile.bed_width:g} x {profile.bed_height:g} mm")
    return PlayerData(
        source="gcode", title=title, points=points, kinds=kinds, colors=np.r_[0, colors],
        palette=palette, times=np.r_[0.0, times], numbers=np.r_[line[0], line] + 1,
        number_label="line", number_total=int(n_lines), total=float(job.total_seconds),
        unit="mm", time_unit="s", y_up=True,
        frame=(0.0, 0.0, float(profile.bed_width), float(profile.bed_height)), info=info)


def gcode_file_player_data(path: str | os.PathLike, *, profile: LaserProfile | None = None) -> PlayerData:
    """`PlayerData` of a G-code file (.gcode, .nc, ...)."""
    return _player_data(load_program(path), os.path.basename(str(path)), profile)
