"""Option ranges, declared once with the option types that use them.

A `Range` says which numbers an option takes, in the library's unit, and how messages and
help texts name it. It lives beside the option type it limits, and everything that builds
that type checks against it: the CLI's click types, the studio's API, batch, edits files
and the bridges give the same one-line message (the CLI's wording) for the same bad value.

Declaring and checking, in the module that owns the option::

    from onestroke.ranges import Range, check_ranges, ranged

    SIDE = Range(0.1, 10_000.0, unit="mm", name="--size")      # one declaration
    ROTATE = Range(-360.0, 360.0, unit="degrees", name="--rotate")

    @dataclass(frozen=True, kw_only=True)
    class PlacementOptions:
        size: float | None = ranged(None, SIDE)               # None: not set, passes
        width: float | None = ranged(None, SIDE.named("--width"))
        rotate: float = ranged(0.0, ROTATE)

        def __post_init__(self) -> None:
            check_ranges(self)     # InputError: "--rotate 400 must be from -360 degrees to 360 degrees"

Reading a declaration elsewhere (never copy its numbers)::

    ranges_of(PlacementOptions)["size"]     # the Range of a field
    ROTATE.check(value, shown="'400deg'")   # a value parsed from text: the message shows the text
    ROTATE.span()                           # "-360-360 degrees", for help texts and tables
    ROTATE.text()                           # "from -360 degrees to 360 degrees"

The CLI's parameter types take a Range (`fabrication.cli.options.Length(SIDE)`); a range
with `scale` shows stored values scaled (power: a fraction stored, percent shown). A
relation between two options (stitch length at least the minimum stitch) stays a check
of its own in `__post_init__`, after `check_ranges`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields, replace

from onestroke.errors import InputError


@dataclass(frozen=True)
class Range:
    """The numbers an option takes.

    low, high: bounds in the library's unit (None: unbounded on that side); low_open /
    high_open: the bound itself is refused. unit: shown after numbers ("mm", "px", "%",
    "degrees", "mm/min"; "" for a bare number). name: how messages name the option, its CLI
    spelling where it has one ("--size"). integer: only whole numbers (not bool). scale:
    shown value = stored value x scale (100 for a fraction shown in percent).
    """

    low: float | None = None
    high: float | None = None
    unit: str = ""
    name: str = "value"
    low_open: bool = False
    high_open: bool = False
    integer: bool = False
    scale: float = 1.0

    def named(self, name: str) -> "Range":
        """The same limits under another option's name (--width beside --size)."""
        return replace(self, name=name)

    def _show(self, value: float, separator: str = "") -> str:
        unit = self.unit if self.unit in ("", "%") else f" {self.unit}"
        return _bound(value * self.scale, separator) + unit

    def text(self) -> str:
        """The range in words, as messages end: 'from 0.1 mm to 10000 mm', 'above 0 to below 1'."""
        low, high = self.low, self.high
        if low is not None and high is not None:
            return (f"{'above' if self.low_open else 'from'} {self._show(low)} "
                    f"{'to below' if self.high_open else 'to'} {self._show(high)}")
        if low is not None:
            return f"{'above' if self.low_open else 'at least'} {self._show(low)}"
        if high is not None:
            return f"{'below' if self.high_open else 'at most'} {self._show(high)}"
        return "any finite number"

    def span(self) -> str:
        """The range for help texts and tables: '0.1-12.7 mm', 'above 0-100 %', 'at least 1'."""
        unit = "" if not self.unit else (self.unit if self.unit == "%" else f" {self.unit}")
        if self.low is None or self.high is None:
            return self.text()
        low, high = _bound(self.low * self.scale, ","), _bound(self.high * self.scale, ",")
        opening = "above " if self.low_open else ""
        closing = "below " if self.high_open else ""
        joint = " to " if low.startswith("-") or high.startswith("-") or opening or closing else "-"
        return f"{opening}{low}{joint}{closing}{high}{unit}"

    def contains(self, value: float) -> bool:
        """Whether the finite number `value` lies within the bounds."""
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            return False
        if self.high is not None and (value >= self.high if self.high_open else value > self.high):
            return False
        return True

    def check(self, value, *, shown: str | None = None):
        """`value` when it is a finite number within the range (a whole one if `integer`), else
        `InputError` naming the option: "--blur 30 must be from 0 px to 25 px". `shown`: how
        the message shows the value (what the user typed, e.g. "'0.01mm'"); default: the
        value scaled, without unit."""
        if not isinstance(value, numbers.Real) or isinstance(value, bool):
            raise InputError(f"{self.name} {value!r} is not a number")
        if shown is not None:
            text = shown
        elif isinstance(value, numbers.Integral) and self.scale == 1:
            text = str(int(value))
        else:
            text = f"{value * self.scale:g}" if math.isfinite(value) else str(value)
        if not math.isfinite(value):
            raise InputError(f"{self.name} {text} is not a finite number")
        if self.integer and not isinstance(value, numbers.Integral):
            raise InputError(f"{self.name} {text} is not a whole number")
        if not self.contains(value):
            raise InputError(f"{self.name} {text} must be {self.text()}")
        return value


def _bound(value: float, separator: str = "") -> str:
    """A bound as people write it: 0.1, 25, 100000 (or 100,000 with separator ",")."""
    if float(value).is_integer() and abs(value) < 1e15:
        return f"{int(value):{separator}d}" if separator else str(int(value))
    return f"{value:g}"


def ranged(default, limits: Range, **field_options):
    """A dataclass field whose values `check_ranges` checks against `limits`."""
    return field(default=default, metadata={"range": limits}, **field_options)


def ranges_of(options_type) -> dict[str, Range]:
    """Field name -> Range of the ranged fields of a dataclass (type or instance)."""
    return {f.name: f.metadata["range"] for f in fields(options_type) if "range" in f.metadata}


def check_ranges(options) -> None:
    """Check every ranged field of the dataclass instance `options` (None passes: not set);
    `InputError` for the first that is out of range, in field order."""
    for f in fields(options):
        limits = f.metadata.get("range")
        value = getattr(options, f.name)
        if limits is not None and value is not None:
            limits.check(value)
