"""`$` lines in a job under --allow-settings: checked as GRBL 1.1h checks them (system.c,
settings.c, gcode.c's jog rules), and the ones that change the job's meaning refused by name."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from fabrication.cli import main
from machines.gcode_program import analyze_program, program_from_text
from machines.grbl_settings import FIRMWARE_DEFAULTS
from machines.system_commands import system_answer

HOMING = {**FIRMWARE_DEFAULTS, 22: 1}

# (line, settings, GRBL's answer when Idle, refused by name, why) - answers from gnea/grbl 1.1h
TABLE = [
    ("$H", FIRMWARE_DEFAULTS, 5, False, "homing disabled ($22=0): STATUS_SETTING_DISABLED"),
    ("$H", HOMING, 0, False, "homing enabled: a homing cycle"),
    ("$HX", HOMING, 3, False, "single-axis homing is not in the default build"),
    ("$J=G91X1", FIRMWARE_DEFAULTS, 22, True, "a jog needs F"),
    ("$J=G91X1F0", FIRMWARE_DEFAULTS, 22, True, "F0 is no feed"),
    ("$J=G1X1F100", FIRMWARE_DEFAULTS, 16, True, "a jog takes no motion command"),
    ("$J=M3X1F100", FIRMWARE_DEFAULTS, 16, True, "nor an M command"),
    ("$J=X1S100F100", FIRMWARE_DEFAULTS, 36, True, "S is an unused word in a jog"),
    ("$J=G91G21X1F100", FIRMWARE_DEFAULTS, 0, True, "valid, but a jog locks out the G-code after it"),
    ("$J", FIRMWARE_DEFAULTS, 3, False, "no '='"),
    ("$999=1", FIRMWARE_DEFAULTS, 3, False, "parameter > 255"),
    ("$200=1", FIRMWARE_DEFAULTS, 3, False, "no such setting"),
    ("$133=1", FIRMWARE_DEFAULTS, 3, False, "only 3 axes"),
    ("$Q", FIRMWARE_DEFAULTS, 2, False, "no setting number to read"),
    ("$32=", FIRMWARE_DEFAULTS, 2, False, "no value"),
    ("$32=1X", FIRMWARE_DEFAULTS, 3, False, "characters after the value"),
    ("$100=-1", FIRMWARE_DEFAULTS, 4, False, "negative value"),
    ("$0=2", FIRMWARE_DEFAULTS, 6, False, "step pulse under 3 us"),
    ("$20=1", FIRMWARE_DEFAULTS, 10, False, "soft limits need homing"),
    ("$20=1", HOMING, 0, False, "with homing they are fine"),
    ("$32=1", FIRMWARE_DEFAULTS, 0, False, "laser mode"),
    ("$C", FIRMWARE_DEFAULTS, 0, True, "check mode"),
    ("$CX", FIRMWARE_DEFAULTS, 3, False, "characters after $C"),
    ("$SLP", FIRMWARE_DEFAULTS, 0, True, "sleep"),
    ("$SL", FIRMWARE_DEFAULTS, 3, False, "only $SLP"),
    ("$RST=*", FIRMWARE_DEFAULTS, 0, True, "restore everything and reset"),
    ("$RST=Q", FIRMWARE_DEFAULTS, 3, True, "no such restore"),
    ("$N0=G1X1F100", FIRMWARE_DEFAULTS, 0, True, "a startup line"),
    ("$N0=G5", FIRMWARE_DEFAULTS, 20, True, "a startup line GRBL's parser refuses"),
    ("$X", FIRMWARE_DEFAULTS, 0, False, "unlock: no effect when not in alarm"),
    ("$$", FIRMWARE_DEFAULTS, 0, False, "settings report"),
    ("$G", FIRMWARE_DEFAULTS, 0, False, "parser state report"),
]


@pytest.mark.parametrize("line, settings, code, named, why", TABLE, ids=[f"{row[0]}-{row[4]}" for row in TABLE])
def test_grbl_answers_each_system_command_as_its_source_says(line, settings, code, named, why):
    answer = system_answer(line, settings, idle=True)
    assert answer.code == code, why
    assert (answer.refused is not None) == named, why


@pytest.mark.parametrize("line, busy_code", [("$H", 8), ("$32=1", 8), ("$Q", 8), ("$$", 8), ("$C", 8),
                                             ("$J=G91X1F100", 8), ("$G", 0), ("$X", 0)])
def test_commands_that_need_idle_fail_behind_running_moves(line, busy_code):
    assert system_answer(line, HOMING, idle=False).code == busy_code


def job(middle: str, *, sync: bool = True) -> str:
    return "\n".join(["G21", "G90", "M4 S0", "G1 X5 Y5 F600 S300", *(["G4 P0"] if sync else []), middle,
                      "G1 X9 Y2", "M5", ""])


def test_the_precheck_follows_the_machine_state_through_the_job():
    errors = lambda text, settings=HOMING: analyze_program(program_from_text(text), settings=settings,  # noqa: E731
                                                            allow_settings=True).errors
    assert errors(job("$H")) == ()  # after G4 P0 the machine is Idle
    assert "error:8" in errors(job("$H", sync=False))[0][1]  # streamed behind a move: not idle
    assert "error:5" in errors(job("$H"), FIRMWARE_DEFAULTS)[0][1]
    # a setting the job stores holds for the lines after it
    assert errors(job("$22=1\nG4 P0\n$H"), FIRMWARE_DEFAULTS) == ()
    assert "check mode" in errors(job("$C"))[0][1]


def test_a_job_setting_laser_mode_itself_passes_the_preflight():
    from machines.job_check import check_job

    machine = {**FIRMWARE_DEFAULTS, 32: 0}
    text = "$32=1\nG21\nM4 S300\nG1 X5 F600\nM5\n"
    stats = analyze_program(program_from_text(text), settings=machine, allow_settings=True)
    assert stats.settings_written == {32: 1.0}
    assert not [p for p in check_job(stats, machine) if p.fatal]


@pytest.mark.parametrize("line, words", [("$H", "error:5"), ("$J=G91X1", "error:22"), ("$J=G1X1F100", "error:16"),
                                         ("$999=1", "error:3"), ("$Q", "error:2"), ("$C", "is refused: $C"),
                                         ("$SLP", "is refused: $SLP"), ("$RST=*", "is refused: $RST=*")])
def test_stream_refuses_before_sending_anything(tmp_path, line, words):
    path = tmp_path / "job.gcode"
    path.write_text(job(line))
    result = CliRunner().invoke(main, ["stream", str(path), "--port", "sim://?speed=100", "--allow-settings"])
    assert result.exit_code == 2, result.output
    assert words in result.output and "line 6" in result.output, result.output
    assert "streamed" not in result.output and "last acknowledged" not in result.output
