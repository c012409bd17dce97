"""Pre-flight: does this job fit this machine? ($32 laser mode, $30 max S, $130/$131 bed.)"""

from __future__ import annotations

from dataclasses import dataclass

from machines.gcode_program import ProgramStats


@dataclass(frozen=True)
class JobProblem:
    """One finding; `fatal` ones stop the job before anything is sent."""

    fatal: bool
    message: str


def check_job(stats: ProgramStats, settings: dict[int, float], *, profile=None) -> list[JobProblem]:
    """Compare what the job does with the machine's `$$` settings (and a LaserProfile, if given).

    Machine coordinates only mean something once the machine is homed ($22=1); without
    homing, only the job's size is checked against the bed and its position is a warning.
    """
    problems: list[JobProblem] = []
    settings = {**settings, **stats.settings_written}  # what the job's own $N= lines store holds
    laser_mode = settings.get(32)
    if stats.uses_laser and laser_mode is not None and not laser_mode:
        problems.append(JobProblem(True, "laser mode is off ($32=0): GRBL would keep the beam on during G0 "
                                         "travel and stop at every power change; set $32=1 first"))
    max_s = settings.get(30)
    if max_s is not None and stats.max_s > max_s + 1e-9:
        problems.append(JobProblem(True, f"the job uses S{stats.max_s:g} but the machine's maximum is "
                                         f"$30={max_s:g}: every power above it burns at 100 %; "
                                         f"regenerate the G-code for max S {max_s:g}"))
    width, height = settings.get(130), settings.get(131)
    if stats.extent is not None and width and height:
        (x0, y0), (x1, y1) = stats.extent
        if x1 - x0 > width + 1e-6 or y1 - y0 > height + 1e-6:
            problems.append(JobProblem(True, f"the job spans {x1 - x0:.1f} x {y1 - y0:.1f} mm but the bed is "
                                             f"{width:g} x {height:g} mm ($130/$131); make it smaller"))
        elif x0 < -1e-6 or y0 < -1e-6 or x1 > width + 1e-6 or y1 > height + 1e-6:
            where = (f"X {x0:.1f}..{x1:.1f}, Y {y0:.1f}..{y1:.1f} mm outside the bed 0..{width:g} x "
                     f"0..{height:g} mm")
            homed = bool(settings.get(22))
            problems.append(JobProblem(homed, f"the job reaches {where}" + (
                "; move the job or its origin" if homed else
                " in machine coordinates (no homing: make sure the head starts at the job origin)")))
    if stats.errors:
        line, text = stats.errors[0]
        more = f" (and {len(stats.errors) - 1} more)" if len(stats.errors) > 1 else ""
        by = "is refused" if stats.codes[0] == 0 else "would be refused by GRBL"  # code 0: refused here
        problems.append(JobProblem(True, f"line {line} {by}: {text}{more}"))
    if profile is not None:
        for number, name, value in ((130, "bed width", profile.bed_width), (131, "bed height", profile.bed_height),
                                    (30, "max power", profile.max_power)):
            machine = settings.get(number)
            if machine is not None and abs(machine - value) > 1e-6:
                problems.append(JobProblem(False, f"the laser profile's {name} is {value:g} but the machine "
                                                  f"says ${number}={machine:g}"))
    return problems
