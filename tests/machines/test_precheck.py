"""The pre-check answers every line as GRBL 1.1h does: ok, or the firmware's error:N.

Each answer below was read off GRBL 1.1h's parser (gnea/grbl grbl/gcode.c, gc_execute_line,
default build: laser mode on, M7 not compiled in) and its error table (doc/csv/
error_codes_en_US.csv). The lines run in order on one machine, so the modal state (feed,
position, motion mode) carries from line to line as on the firmware.
"""

from __future__ import annotations

import pytest

from machines.gcode_interpreter import GcodeError, GcodeInterpreter
from machines.gcode_program import analyze_program, program_from_text
from machines.grbl_settings import FIRMWARE_DEFAULTS

# (line, GRBL's answer, why)
TABLE = [
    ("G21", "ok", "mm"),
    ("G90", "ok", "absolute"),
    ("G1X10", "error:22", "feed rate undefined"),
    ("G1", "error:22", "an explicit G1 needs a feed even without axis words"),
    ("G0X10Y10", "ok", "rapid needs no feed"),
    ("G1X20Y10F1000", "ok", ""),
    ("G1X70Y10K1", "error:36", "K is used by no command on the line"),
    ("G1X20L5", "error:36", "L belongs to G10 only"),
    ("G0X1P1", "error:36", "P without G4/G10"),
    ("G4", "error:28", "dwell without P"),
    ("G4P0.1", "ok", ""),
    ("G4P-1", "error:4", "negative P"),
    ("F-5", "error:4", "negative F"),
    ("S-1", "error:4", "negative S"),
    ("G1X1X2", "error:25", "word repeated"),
    ("G0G1X1", "error:24", "two commands that use axis words"),
    ("G17G18", "error:21", "two of one modal group"),
    ("M3M5", "error:21", "two spindle commands"),
    ("G5X1", "error:20", "unsupported G"),
    ("M6", "error:20", "tool change unsupported"),
    ("M7", "error:20", "mist coolant is not in the default build"),
    ("G1.5X1", "error:23", "G1.5: command must be an integer"),
    ("M3.5", "error:23", "no Mxx.x commands"),
    ("G38.1X1", "error:20", "only G38.2-G38.5 exist"),
    ("G38.2X5F100", "ok", "probe toward (accepted by the parser)"),
    ("G38.3X6", "ok", "probe toward, no error"),
    ("G38.4X7", "ok", "probe away"),
    ("G38.5X8", "ok", "probe away, no error"),
    ("G38.2X8", "error:33", "probe target equals the current position"),
    ("G38.2", "error:26", "probe without axis words"),
    ("X", "error:2", "letter without a number"),
    ("1X2", "error:1", "number without a letter"),
    ("G80X1", "error:31", "axis words with G80"),
    ("G80", "ok", "motion mode cancel"),
    ("X5", "error:31", "axis words while G80 is the motion mode"),
    ("G1X10Y10", "ok", "feed is still F100"),
    ("G2X20Y10I5J0", "ok", "half circle"),
    ("G2X30Y10", "error:35", "arc without offsets or radius"),
    ("G2X30Y10R1", "error:34", "radius smaller than half the chord"),
    ("G2X20Y10R5", "error:33", "radius arc ending where it starts"),
    ("G2Z5I1", "error:32", "no axis word in the plane"),
    ("G3X40Y10I5J3", "error:33", "end point off the arc's circle"),
    ("G2X30Y10R5I1", "error:36", "I unused in radius mode"),
    ("G10L2P1X0", "ok", "set G54"),
    ("G10L3P1X0", "error:20", "unsupported L"),
    ("G10P1X0", "error:20", "L missing: L0 unsupported"),
    ("G10L2P7X0", "error:29", "no such coordinate system"),
    ("G10L2P1", "error:26", "G10 without axis words"),
    ("G92", "error:26", "G92 without axis words"),
    ("G53G2X1Y1I1", "error:30", "G53 only with G0/G1"),
    ("G28.2", "error:20", "G28.2 does not exist"),
    ("G91.1", "ok", "incremental arc distance (the default)"),
    ("G90.1", "error:20", "absolute arc distance unsupported"),
    ("G43.1Z1", "ok", "dynamic tool length offset"),
    ("G43.1X1", "error:37", "G43.1 on an axis other than Z"),
    ("G43", "error:20", "only G43.1"),
    ("G49", "ok", "cancel tool length offset"),
    ("N99999999G0X1", "error:27", "line number above 10,000,000"),
    ("T256", "error:38", "tool number above 255"),
    ("G61", "ok", "exact path (the only path mode)"),
    ("G61.1", "error:20", "exact stop mode unsupported"),
    ("G64", "error:20", "path blending unsupported"),
    ("M1", "ok", "optional stop: ignored"),
    ("G93G1X5", "error:22", "inverse time without F"),
    ("G93G1X5F10", "ok", "inverse time with F"),
    ("G94", "ok", "back to units per minute"),
    ("G1X6", "error:22", "feed undefined after G93 -> G94"),
    ("G1X6F500M8", "ok", "flood coolant (air assist)"),
    ("G92X0Y0", "ok", "offset"),
    ("M2", "ok", "program end"),
]


def _answer(interp: GcodeInterpreter, line: str) -> str:
    try:
        interp.execute(line)
    except GcodeError as error:
        return f"error:{error.code}"
    return "ok"


def test_precheck_answers_like_grbl_line_by_line():
    assert len(TABLE) >= 40
    interp = GcodeInterpreter()
    got = [(line, _answer(interp, line)) for line, _, _ in TABLE]
    assert got == [(line, expected) for line, expected, _ in TABLE]


def test_job_precheck_reports_the_same_codes_with_file_lines():
    program = program_from_text("\n".join(line for line, _, _ in TABLE))
    stats = analyze_program(program)
    refused = [(number, f"error:{code}") for (number, _), code in zip(stats.errors, stats.codes)]
    expected = [(k + 1, answer) for k, (_, answer, _) in enumerate(TABLE) if answer != "ok"]
    assert refused == expected


@pytest.mark.parametrize("line", ["$RST=*", "$30=255", "$32=0", "$H", "$X", "$$"])
def test_dollar_commands_in_a_job_are_refused_unless_allowed(line):
    program = program_from_text(f"G21\n{line}\nG0X1\n")
    refused = analyze_program(program, allow_settings=False).errors
    assert [number for number, _ in refused] == [2] and "--allow-settings" in refused[0][1]
    allowed = analyze_program(program, allow_settings=True, settings={**FIRMWARE_DEFAULTS, 22: 1}).errors
    # allowed lines are still checked: $RST=* would wipe what the job relies on
    assert allowed == (() if line != "$RST=*" else ((2, allowed[0][1]),))
