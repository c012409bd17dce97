"""Resume a job from a chosen file line after a failure: restore GRBL's modal state, go to
where that line starts with the beam off, then stream the rest of the file.
"""

from __future__ import annotations

from machines.gcode_interpreter import GcodeError, GcodeInterpreter, GcodeState, MachineConfig
from machines.gcode_program import Program
from onestroke.errors import InputError

# Lines that change work offsets: skipping them changes where later lines go.
_OFFSET_WORDS = ("G92", "G10", "G28.1", "G30.1", "G55", "G56", "G57", "G58", "G59")


def resume_program(program: Program, from_line: int, *, start=(0.0, 0.0, 0.0)) -> Program:
    """`program` from file line `from_line` on, after a preamble (file line number 0).

    The preamble turns the beam off (M5), moves in machine coordinates (G53 G0) to where
    `from_line` starts, and restores units, distance mode, feed, air assist and laser mode
    and power as the skipped lines left them. `start`: machine position (mm) the job began
    from. InputError if `from_line` is not a G-code line of the file, or if a skipped line
    changes work offsets (the resumed moves would land elsewhere).
    """
    numbers = [number for number, _ in program.lines]
    if from_line not in numbers:
        raise InputError(f"--from-line {from_line} is not a G-code line of {program.source}; use one of "
                         f"{numbers[0]}..{numbers[-1]} that holds G-code (see the error's line number)")
    state = GcodeState(position=[float(v) for v in start])
    interp = GcodeInterpreter(MachineConfig(), state)
    index = numbers.index(from_line)
    for number, text in program.lines[:index]:
        if text.startswith("$"):
            continue
        if any(word in text for word in _OFFSET_WORDS):
            raise InputError(f"line {number} ({text}) changes work offsets; resuming after it is not supported, "
                             "run the whole job again")
        try:
            interp.execute(text)
        except GcodeError as error:
            raise InputError(f"line {number} ({text}) would be refused by GRBL (error:{error.code}); "
                             "fix the file before resuming") from None
    st = interp.state
    x, y, z = st.position
    unit = "G20" if st.inches else "G21"
    scale = 25.4 if st.inches else 1.0
    preamble = ["M5", "G21", "G90", f"G{st.plane}", f"G53G0X{x:.3f}Y{y:.3f}" + (f"Z{z:.3f}" if z else "")]
    preamble += [unit, "G90" if st.absolute else "G91", "G93" if st.inverse_time else "G94"]
    if st.feed > 0 and not st.inverse_time:
        preamble.append(f"F{st.feed / scale:g}")
    preamble += sorted(st.coolant)
    if st.spindle != "M5":
        preamble.append(f"{st.spindle}S{st.s:g}")
    preamble.append(f"G{st.motion}" if st.motion in (0, 1, 2, 3) else "G80")
    lines = tuple((0, line) for line in preamble) + program.lines[index:]
    return Program(program.source, lines)
