"""Parsing of unit strings given by users and profiles ("90mm", "3.5in", "1500mm/min", "60%").

All lengths come back in millimetres, speeds in mm/min, fractions in [0, 1].
"""

from __future__ import annotations

import math
import re

from onestroke.errors import InputError

MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "pt": 25.4 / 72, "px": 25.4 / 96}
# The one number grammar of every value a user types (options, unit strings, sim:// values):
# ASCII decimal digits, an optional sign, point and exponent. Not Python's float()/int(),
# which also take "1_0", "nan", "infinity" and Arabic-Indic or full-width digits.
_NUMBER = r"([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)"
_INTEGER = re.compile(r"^[ \t]*([-+]?[0-9]+)[ \t]*$", re.ASCII)
_PLAIN = re.compile(rf"^[ \t]*{_NUMBER}[ \t]*$", re.ASCII)
_LENGTH = re.compile(rf"^\s*{_NUMBER}\s*([a-zA-Z]*)\s*$", re.ASCII)
_SPEED = re.compile(rf"^\s*{_NUMBER}\s*(?:([a-zA-Z]+)\s*/\s*(min|s))?\s*$", re.ASCII)
_PERCENT = re.compile(rf"^\s*{_NUMBER}\s*(%?)\s*$", re.ASCII)


def parse_number(text: str | float, *, what: str = "value") -> float:
    """A number written in ASCII decimal ("2.5", "-3", "1e-3"), as a float (possibly
    infinite when the exponent overflows: range checks refuse it)."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return float(text)
    match = _PLAIN.match(str(text))
    if not match:
        raise InputError(f"{what} {text!r} is not a number; write it with the digits 0-9, e.g. 2.5")
    return float(match.group(1))


def parse_integer(text: str | int, *, what: str = "value") -> int:
    """A whole number written in ASCII decimal ("3", "-1")."""
    if isinstance(text, int) and not isinstance(text, bool):
        return text
    match = _INTEGER.match(str(text))
    if not match:
        raise InputError(f"{what} {text!r} is not a whole number; write it with the digits 0-9, e.g. 3")
    return int(match.group(1))


def parse_length(text: str | float, *, default_unit: str = "mm", what: str = "length") -> float:
    """Return a length in mm from "90mm", "3.5in", "9cm", "12px" (96 px/in) or a bare number."""
    if isinstance(text, (int, float)):
        return _finite(float(text) * MM_PER_UNIT[default_unit], text, what)
    match = _LENGTH.match(str(text))
    if not match:
        raise InputError(f"{what} {text!r} is not a length; use e.g. '90mm', '3.5in', '9cm'")
    value, unit = float(match.group(1)), (match.group(2).lower() or default_unit)
    if unit not in MM_PER_UNIT:
        raise InputError(
            f"{what} {text!r} has unknown unit {unit!r}; use one of {', '.join(MM_PER_UNIT)}"
        )
    return _finite(value * MM_PER_UNIT[unit], text, what)


def _finite(value: float, text, what: str) -> float:
    # "1e999" parses to inf: refuse it here so no caller meets an infinite length or speed.
    if not math.isfinite(value):
        raise InputError(f"{what} {text!r} is not a finite number")
    return value


def parse_positive_length(text: str | float, *, what: str = "length") -> float:
    """Like `parse_length` but refuse zero and negative values."""
    value = parse_length(text, what=what)
    if not value > 0:
        raise InputError(f"{what} {text!r} must be greater than zero")
    return value


def parse_speed(text: str | float, *, what: str = "feed") -> float:
    """Return a speed in mm/min from "1500mm/min", "25mm/s", "60in/min" or a bare number (mm/min)."""
    if isinstance(text, (int, float)):
        return _finite(float(text), text, what)
    match = _SPEED.match(str(text))
    if not match:
        raise InputError(f"{what} {text!r} is not a speed; use e.g. '1500mm/min' or '25mm/s'")
    value = float(match.group(1))
    unit, per = (match.group(2) or "mm").lower(), match.group(3) or "min"
    if unit not in MM_PER_UNIT:
        raise InputError(f"{what} {text!r} has unknown unit {unit!r}; use mm/min, mm/s, in/min")
    return _finite(value * MM_PER_UNIT[unit] * (60.0 if per == "s" else 1.0), text, what)


def parse_fraction(text: str | float, *, what: str = "power") -> float:
    """Return a fraction in [0, 1] from "60%" (or a bare number read as percent)."""
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        match = _PERCENT.match(str(text))
        if not match:
            raise InputError(f"{what} {text!r} is not a percentage; use e.g. '60%'")
        value = float(match.group(1))
    if not 0.0 <= value <= 100.0:
        raise InputError(f"{what} {text!r} must lie between 0% and 100%")
    return value / 100.0


def parse_size_pair(text: str, *, what: str = "size") -> tuple[float, float]:
    """Return (width, height) in mm from "100x100", "130x180mm", "4inx4in"."""
    parts = re.split(r"\s*[xX×]\s*", str(text).strip())
    if len(parts) != 2:
        raise InputError(f"{what} {text!r} is not WxH; use e.g. '100x100' or '130x180mm'")
    unit = re.sub(r"^[-+.0-9eE]+", "", parts[1]) or "mm"
    first = parts[0] if re.search(r"[a-zA-Z]$", parts[0]) else parts[0] + unit
    w = parse_positive_length(first, what=what)
    h = parse_positive_length(parts[1] if re.search(r"[a-zA-Z]$", parts[1]) else parts[1] + "mm", what=what)
    return w, h
