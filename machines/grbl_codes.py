"""GRBL 1.1 error, alarm and setting codes with their meanings (from gnea/grbl doc/csv)."""

from __future__ import annotations

# error:N -> (short name, meaning)
ERROR_CODES: dict[int, tuple[str, str]] = {
    1: ("Expected command letter", "G-code words consist of a letter and a value; letter was not found"),
    2: ("Bad number format", "missing the expected G-code word value or numeric value format is not valid"),
    3: ("Invalid statement", "'$' system command was not recognized or supported"),
    4: ("Value < 0", "negative value received for an expected positive value"),
    5: ("Setting disabled", "homing cycle is not enabled via settings ($22)"),
    6: ("Value < 3 usec", "minimum step pulse time must be greater than 3 usec"),
    7: ("EEPROM read fail", "EEPROM read failed; affected settings restored to defaults"),
    8: ("Not idle", "'$' command cannot be used unless GRBL is Idle"),
    9: ("G-code lock", "G-code is locked out during alarm or jog state"),
    10: ("Homing not enabled", "soft limits cannot be enabled without homing also enabled"),
    11: ("Line overflow", "max characters per line exceeded; line was not executed"),
    12: ("Step rate > 30kHz", "'$' setting value causes the step rate to exceed the maximum supported"),
    13: ("Check Door", "safety door detected as opened and door state initiated"),
    14: ("Line length exceeded", "build info or startup line exceeded EEPROM line length limit"),
    15: ("Travel exceeded", "jog target exceeds machine travel; jog ignored"),
    16: ("Invalid jog command", "jog command has no '=' or contains prohibited g-code"),
    17: ("Setting disabled", "laser mode requires PWM output"),
    20: ("Unsupported command", "unsupported or invalid g-code command found in block"),
    21: ("Modal group violation", "more than one g-code command from the same modal group found in block"),
    22: ("Undefined feed rate", "feed rate has not yet been set or is undefined"),
    23: ("Invalid gcode ID:23", "g-code command in block requires an integer value"),
    24: ("Invalid gcode ID:24", "more than one g-code command that requires axis words found in block"),
    25: ("Invalid gcode ID:25", "repeated g-code word found in block"),
    26: ("Invalid gcode ID:26", "no axis words found in block for g-code command or modal state which requires them"),
    27: ("Invalid gcode ID:27", "line number value is invalid"),
    28: ("Invalid gcode ID:28", "g-code command is missing a required value word"),
    29: ("Invalid gcode ID:29", "G59.x work coordinate systems are not supported"),
    30: ("Invalid gcode ID:30", "G53 only allowed with G0 and G1 motion modes"),
    31: ("Invalid gcode ID:31", "axis words found in block when no command or modal state uses them"),
    32: ("Invalid gcode ID:32", "G2 and G3 arcs require at least one in-plane axis word"),
    33: ("Invalid gcode ID:33", "motion command target is invalid"),
    34: ("Invalid gcode ID:34", "arc radius value is invalid"),
    35: ("Invalid gcode ID:35", "G2 and G3 arcs require at least one in-plane offset word"),
    36: ("Invalid gcode ID:36", "unused value words found in block"),
    37: ("Invalid gcode ID:37", "G43.1 dynamic tool length offset is not assigned to configured tool length axis"),
    38: ("Invalid gcode ID:38", "tool number greater than max supported value"),
}

# ALARM:N -> (short name, meaning)
ALARM_CODES: dict[int, tuple[str, str]] = {
    1: ("Hard limit", "a limit switch was triggered; machine position is likely lost, re-homing is recommended"),
    2: ("Soft limit", "a motion target exceeds the machine travel ($130/$131); position retained, safe to unlock"),
    3: ("Abort during cycle", "reset while in motion; machine position is likely lost, re-homing is recommended"),
    4: ("Probe fail", "probe is not in the expected initial state before the probe cycle"),
    5: ("Probe fail", "probe did not contact the workpiece within the programmed travel"),
    6: ("Homing fail", "the active homing cycle was reset"),
    7: ("Homing fail", "safety door was opened during the homing cycle"),
    8: ("Homing fail", "pull-off travel failed to clear the limit switch; increase pull-off or check wiring"),
    9: ("Homing fail", "could not find the limit switch within search distance; check max travel or wiring"),
    10: ("Homing fail", "on dual-axis machines, could not find the second limit switch for self-squaring"),
}

# $N -> (name, unit); the settings onestroke reads or the emulator exposes.
SETTING_NAMES: dict[int, tuple[str, str]] = {
    0: ("step pulse", "us"), 1: ("step idle delay", "ms"), 2: ("step port invert", "mask"),
    3: ("direction port invert", "mask"), 4: ("step enable invert", "bool"), 5: ("limit pins invert", "bool"),
    6: ("probe pin invert", "bool"), 10: ("status report options", "mask"), 11: ("junction deviation", "mm"),
    12: ("arc tolerance", "mm"), 13: ("report in inches", "bool"), 20: ("soft limits", "bool"),
    21: ("hard limits", "bool"), 22: ("homing cycle", "bool"), 23: ("homing direction invert", "mask"),
    24: ("homing feed", "mm/min"), 25: ("homing seek", "mm/min"), 26: ("homing debounce", "ms"),
    27: ("homing pull-off", "mm"), 30: ("max spindle speed", "RPM/S"), 31: ("min spindle speed", "RPM/S"),
    32: ("laser mode", "bool"), 100: ("x steps/mm", "step/mm"), 101: ("y steps/mm", "step/mm"),
    102: ("z steps/mm", "step/mm"), 110: ("x max rate", "mm/min"), 111: ("y max rate", "mm/min"),
    112: ("z max rate", "mm/min"), 120: ("x acceleration", "mm/s^2"), 121: ("y acceleration", "mm/s^2"),
    122: ("z acceleration", "mm/s^2"), 130: ("x max travel", "mm"), 131: ("y max travel", "mm"),
    132: ("z max travel", "mm"),
}


def describe_error(code: int) -> str:
    """One-line text for `error:code`, e.g. "error:20 (Unsupported command: ...)"."""
    name, meaning = ERROR_CODES.get(code, ("Unknown error", "not in the GRBL 1.1 table"))
    return f"error:{code} ({name}: {meaning})"


def describe_alarm(code: int) -> str:
    """One-line text for `ALARM:code`, including how to recover."""
    name, meaning = ALARM_CODES.get(code, ("Unknown alarm", "not in the GRBL 1.1 table"))
    if code in (1, 3, 6, 7, 8, 9, 10):
        fix = "check the machine, then home with $H (or unlock with $X if it has no homing switches)"
    else:
        fix = "unlock with $X (or home with $H)"
    return f"ALARM:{code} ({name}: {meaning}); {fix}"
