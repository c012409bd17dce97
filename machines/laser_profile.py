"""Laser machine profiles: GRBL 1.1 settings as TOML data with unit strings.

A profile holds what the planner, the G-code writer and the time estimate need to know
about one machine: bed size, max S (`$30`), laser mode (`$32`), per-axis max rates and
accelerations (`$110/$111/$120/$121`), junction deviation (`$11`), arc tolerance (`$12`),
steps per mm (`$100/$101`), the serial RX buffer, the planner's block count, the baud
rate and the controller's time to parse and plan one line (`parse_time`: 2 ms for an
ATmega328 at 16 MHz, the Arduino Uno GRBL 1.1h targets). The
format is documented in docs/laser.md; `profiles/laser-default.toml` is the default.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from onestroke.textfile import read_text
from onestroke.units import parse_positive_length, parse_size_pair, parse_speed

DEFAULT_PROFILE_PATH = Path(__file__).with_name("profiles") / "laser-default.toml"

# What GRBL-family controllers and their machines have; beyond these no machine goes, and
# each bounds the work of one job's estimate and preview (the studio answers within 2 s):
# a bed side (diode lasers 300-1,000 mm; GRBL routers with a laser up to a 4 x 8 ft sheet,
# 1,220 x 2,440 mm);
BED_SIDE = Range(0.0, 2500.0, unit="mm", name="bed side", low_open=True)
# $12, the arc tolerance GRBL cuts G2/G3 into chords within (default 0.002 mm; chords per
# arc grow as 1 / sqrt of it);
ARC_TOLERANCE = Range(0.001, 1.0, unit="mm", name="arc_tolerance ($12)")
# the serial receive buffer (GRBL on an ATmega328: 128 bytes; grblHAL: 1,024) and the
# planner's look-ahead (GRBL: 15 usable blocks, grbl-Mega 35, grblHAL boards up to 256).
RX_BUFFER = Range(16, 4096, unit="bytes", name="rx_buffer", integer=True)
PLANNER_BLOCKS = Range(2, 256, name="planner_blocks", integer=True)

_ACCEL = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(?:(mm|in|m)\s*/\s*(s|sec|min)\s*(?:\^?\s*2|²))?\s*$")


@dataclass(frozen=True, kw_only=True)
class LaserProfile:
    """One GRBL laser machine. Lengths in mm, rates in mm/min, accelerations in mm/s².

    The bed spans [0, bed_width] x [0, bed_height] in machine coordinates (+y up).
    """

    name: str = "GRBL laser"
    bed_width: float = ranged(400.0, BED_SIDE.named("bed width"))
    bed_height: float = ranged(400.0, BED_SIDE.named("bed height"))
    max_power: float = 1000.0
    laser_mode: bool = True
    air_assist: bool = False
    max_rate_x: float = 6000.0
    max_rate_y: float = 6000.0
    acceleration_x: float = 500.0
    acceleration_y: float = 500.0
    junction_deviation: float = 0.01
    arc_tolerance: float = ranged(0.002, ARC_TOLERANCE)
    steps_per_mm_x: float = 80.0
    steps_per_mm_y: float = 80.0
    rx_buffer: int = ranged(128, RX_BUFFER)
    planner_blocks: int = ranged(15, PLANNER_BLOCKS)
    baud: int = 115200
    parse_time: float = 0.002

    def __post_init__(self) -> None:
        for name in ("bed_width", "bed_height", "max_power", "max_rate_x", "max_rate_y",
                     "acceleration_x", "acceleration_y", "junction_deviation", "arc_tolerance",
                     "steps_per_mm_x", "steps_per_mm_y"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0 and value < float("inf")):
                raise InputError(f"laser profile {self.name!r}: {name} {value!r} must be a positive number")
        if not (isinstance(self.baud, int) and self.baud > 0):
            raise InputError(f"laser profile {self.name!r}: baud {self.baud!r} must be a positive integer")
        if not (isinstance(self.parse_time, (int, float)) and 0 <= self.parse_time < 1):
            raise InputError(f"laser profile {self.name!r}: parse_time {self.parse_time!r} must be seconds in [0, 1)")
        try:
            check_ranges(self)
        except InputError as error:
            raise InputError(f"laser profile {self.name!r}: {error}") from None

    @property
    def rapid_rate(self) -> float:
        """The slower axis' max rate, mm/min (a safe single figure for travel speed)."""
        return min(self.max_rate_x, self.max_rate_y)


def parse_acceleration(text: str | float, *, what: str = "acceleration") -> float:
    """Return mm/s² from "500mm/s^2", "500 mm/s²", "1800000mm/min^2" or a bare number (mm/s²)."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return float(text)
    match = _ACCEL.match(str(text))
    if not match:
        raise InputError(f"{what} {text!r} is not an acceleration; use e.g. '500mm/s^2'")
    value = float(match.group(1))
    unit = {"mm": 1.0, "in": 25.4, "m": 1000.0}[match.group(2) or "mm"]
    per = match.group(3) or "s"
    return value * unit / (3600.0 if per == "min" else 1.0)


def _number(value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{what} {value!r} must be a number")
    return float(value)


def _flag(value, what: str) -> bool:
    if not isinstance(value, bool):
        raise InputError(f"{what} {value!r} must be true or false")
    return value


def _integer(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{what} {value!r} must be a whole number")
    return value


def _seconds(value, what: str) -> float:
    if isinstance(value, str) and value.strip().endswith("ms"):
        return _number(float(value.strip()[:-2]), what) / 1000.0
    if isinstance(value, str) and value.strip().endswith("s"):
        value = float(value.strip()[:-1])
    return _number(value, what)


# key in the TOML table -> (profile field, converter)
_FIELDS = {
    "laser": {
        "max_power": ("max_power", _number),
        "laser_mode": ("laser_mode", _flag),
        "air_assist": ("air_assist", _flag),
    },
    "motion": {
        "max_rate_x": ("max_rate_x", lambda v, w: parse_speed(v, what=w)),
        "max_rate_y": ("max_rate_y", lambda v, w: parse_speed(v, what=w)),
        "acceleration_x": ("acceleration_x", lambda v, w: parse_acceleration(v, what=w)),
        "acceleration_y": ("acceleration_y", lambda v, w: parse_acceleration(v, what=w)),
        "junction_deviation": ("junction_deviation", lambda v, w: parse_positive_length(v, what=w)),
        "arc_tolerance": ("arc_tolerance", lambda v, w: parse_positive_length(v, what=w)),
        "steps_per_mm_x": ("steps_per_mm_x", _number),
        "steps_per_mm_y": ("steps_per_mm_y", _number),
    },
    "controller": {
        "rx_buffer": ("rx_buffer", _integer),
        "planner_blocks": ("planner_blocks", _integer),
        "baud": ("baud", _integer),
        "parse_time": ("parse_time", _seconds),
    },
}


def laser_profile_from_dict(data: dict, *, source: str = "profile") -> LaserProfile:
    """Build a `LaserProfile` from the parsed TOML tables (see docs/laser.md)."""
    known_tables = {"name", "bed", *_FIELDS}
    unknown = sorted(set(data) - known_tables)
    if unknown:
        raise InputError(f"{source}: unknown key(s) {', '.join(unknown)}; "
                         f"use name, bed, laser, motion, controller")
    values: dict = {}
    if "name" in data:
        values["name"] = str(data["name"])
    bed = data.get("bed", {})
    if not isinstance(bed, dict):
        raise InputError(f"{source}: [bed] must be a table")
    for key in bed:
        if key not in ("size", "width", "height"):
            raise InputError(f"{source}: unknown key bed.{key}; use size, or width and height")
    if "size" in bed:
        values["bed_width"], values["bed_height"] = parse_size_pair(str(bed["size"]), what=f"{source}: bed.size")
    if "width" in bed:
        values["bed_width"] = parse_positive_length(bed["width"], what=f"{source}: bed.width")
    if "height" in bed:
        values["bed_height"] = parse_positive_length(bed["height"], what=f"{source}: bed.height")
    for table, fields in _FIELDS.items():
        section = data.get(table, {})
        if not isinstance(section, dict):
            raise InputError(f"{source}: [{table}] must be a table")
        for key, value in section.items():
            if key not in fields:
                raise InputError(f"{source}: unknown key {table}.{key}; use {', '.join(fields)}")
            field_name, convert = fields[key]
            values[field_name] = convert(value, f"{source}: {table}.{key}")
    return LaserProfile(**values)


def laser_profile_from_text(text: str, *, source: str = "laser profile") -> LaserProfile:
    """Parse and check the text of a laser profile TOML file; `source` names it in errors."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{source} is not valid TOML: {error}") from None
    return laser_profile_from_dict(data, source=source)


def bundled_laser_profiles() -> tuple[Path, ...]:
    """The laser profiles shipped with onestroke (`profiles/laser-*.toml`), the default first."""
    others = sorted(p for p in DEFAULT_PROFILE_PATH.parent.glob("laser-*.toml") if p != DEFAULT_PROFILE_PATH)
    return (DEFAULT_PROFILE_PATH, *others)


def load_laser_profile(path: str | os.PathLike | None = None) -> LaserProfile:
    """Read a laser profile TOML file; `None` gives the shipped default profile."""
    path = Path(path) if path is not None else DEFAULT_PROFILE_PATH
    text = read_text(path, what="laser profile", expect="a TOML file")
    return laser_profile_from_text(text, source=f"laser profile {path.name!r}")
