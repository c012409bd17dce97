"""G-code read back for the laser tests: what GRBL 1.1h refuses and the moves it reads."""

from __future__ import annotations


def grbl_refusals(lines) -> list:
    """(file line, reason) of every line GRBL 1.1h would refuse, `$` commands included."""
    from machines.gcode_program import analyze_program, program_from_lines

    return list(analyze_program(program_from_lines(lines), allow_settings=False).errors)


def parse_gcode(lines):
    """Every motion command of `lines` as GRBL reads them (`machines.gcode_program.GcodeMoves`)."""
    from machines.job_time import read_moves
    from machines.laser_profile import load_laser_profile

    return read_moves(lines, load_laser_profile())[0]
