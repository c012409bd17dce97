"""CLI options declared once: click parameter types over `onestroke.units` and one decorator
per option group (drawing input, placement, output, machine).

Every command spells and checks an option the same way. Values are checked while click
parses the command line, before any file is read or written; a bad value raises
`InputError` (one line, exit 2) naming the flag and its documented range. This module
imports no numpy or library package at import time: `onestroke --help` and the start of
every command stay fast. Values come back in the library's units (mm, mm/min, percent),
which `onestroke.units` and `job_options` read back unchanged.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import click

from onestroke import units
from onestroke.errors import InputError

from onestroke.ranges import Range, ranges_of


def _flag(param: click.Parameter | None) -> str:
    """The option's long spelling (--size) or the argument's name (SOURCE), for messages."""
    if param is None:
        return "value"
    if isinstance(param, click.Argument):
        return param.human_readable_name
    return max(param.opts, key=len)


class _Ranged(click.ParamType):
    """Base of the numeric types: parse, then check against the option's declared `Range`
    (`onestroke.ranges`), named by the flag it is given as."""

    quote = True  # lengths, speeds, percentages: show the typed text with its unit in quotes

    def __init__(self, limits: Range | None = None) -> None:
        self.limits = limits if limits is not None else Range()

    def parse(self, text, what: str) -> float:
        """The number in the Range's unit."""
        raise NotImplementedError

    def returned(self, number: float):
        """What the command receives (the Range's unit unless a type says otherwise)."""
        return number

    def convert(self, value, param, ctx):
        what = _flag(param)
        number = self.parse(value, what)
        shown = repr(value) if self.quote else str(value).strip()
        return self.returned(self.limits.named(what).check(number, shown=shown))

    def get_metavar(self, param, ctx=None) -> str:
        return self.name.upper()


class Number(_Ranged):
    """A plain finite float (degrees, px, a fraction) within its declared range."""

    name = "number"
    quote = False

    def parse(self, text, what: str) -> float:
        return units.parse_number(text, what=what)


class Integer(_Ranged):
    """An integer within its declared range."""

    name = "integer"
    quote = False

    def parse(self, text, what: str) -> int:
        return units.parse_integer(text, what=what)


class Length(_Ranged):
    """A length with a unit ("2.5mm", "3in", "9cm"; a bare number is mm), returned in mm."""

    name = "length"

    def parse(self, text, what: str) -> float:
        return units.parse_length(text, what=what)


class Speed(_Ranged):
    """A speed ("1500mm/min", "25mm/s"; a bare number is mm/min), returned in mm/min."""

    name = "speed"

    def parse(self, text, what: str) -> float:
        return units.parse_speed(text, what=what)


class Percent(_Ranged):
    """A percentage ("60%"; a bare number is percent) checked as the fraction its Range
    declares (scale 100), returned in percent (0-100), which
    `onestroke.units.parse_fraction` reads back as the same value."""

    name = "percent"

    def parse(self, text, what: str) -> float:
        return units.parse_fraction(text, what=what)

    def returned(self, number: float) -> float:
        return number * 100.0


class InputFile(click.ParamType):
    """An existing, readable file (not a folder): checked before any work."""

    name = "file"

    def convert(self, value, param, ctx):
        from onestroke.paths import check_input_file

        what = "input file" if isinstance(param, click.Argument) or param is None else _flag(param)
        return check_input_file(value, what=what)


class OutputFile(click.ParamType):
    """A file to write, with one of `suffixes`, in an existing writable folder."""

    name = "file"

    def __init__(self, suffixes: tuple[str, ...]) -> None:
        self.suffixes = tuple(s.lower() for s in suffixes)

    def convert(self, value, param, ctx):
        from onestroke.atomic import check_writable

        path = os.fspath(value)
        suffix = os.path.splitext(path)[1].lower()
        if self.suffixes and suffix not in self.suffixes:
            raise InputError(f"cannot write {path!r} ({_flag(param)}): {suffix or 'no extension'!r} is not "
                             "supported; use a "
                             f"{', '.join(self.suffixes[:-1])}{' or ' if len(self.suffixes) > 1 else ''}"
                             f"{self.suffixes[-1]} file")
        check_writable(path)
        return path


class Port(click.ParamType):
    """A serial device path, a pyserial URL, or `sim://[?options]` (nothing between // and ?)."""

    name = "port"

    def convert(self, value, param, ctx):
        text = str(value).strip()
        if not text:
            raise InputError(f"{_flag(param)} is empty; give a serial port such as /dev/ttyUSB0 or COM3 "
                             "(onestroke ports lists them), or sim:// for a dry run")
        if text.lower().startswith("sim:"):
            import urllib.parse

            parts = urllib.parse.urlsplit(text)
            if not text.lower().startswith("sim://") or parts.netloc or parts.path not in ("", "/"):
                raise InputError(f"{_flag(param)} {text!r}: the emulator is spelled sim:// with options after "
                                 "'?', e.g. sim://?speed=20")
            from machines.sim_url.protocol_sim import parse_sim_url

            try:  # every value now, not when the port opens after the work
                parse_sim_url(text)
            except ValueError as error:
                raise InputError(f"{_flag(param)} {text!r}: {error}") from None
        return text


class BaudRate(Integer):
    """One of the serial rates GRBL boards use (`machines.stream_types.BAUD_RATES`)."""

    name = "baud"

    def convert(self, value, param, ctx):
        from machines.stream_types import parse_baud

        return parse_baud(value, name=_flag(param))


# -- decorators ---------------------------------------------------------------------------------

def _apply(function: Callable, decorators: list[Callable]) -> Callable:
    for decorator in reversed(decorators):
        function = decorator(function)
    return function


def input_argument(name: str = "source", **kwargs) -> Callable:
    """The drawing or file a command reads: must exist and be a readable file."""
    return click.argument(name, type=InputFile(), **kwargs)


def output_option(*suffixes: str, help: str, required: bool = True, flags: tuple[str, ...] = ("-o", "--output"),
                  dest: str | None = None) -> Callable:
    """An output file option with its accepted suffixes, checked writable before any work."""
    names = flags + ((dest,) if dest else ())
    return click.option(*names, required=required, default=None, type=OutputFile(suffixes), help=help)


def drawing_input_options(function: Callable | None = None, *, prefix: str = "") -> Callable:
    """--multi, --threshold, --blur, --classifier: how a raster drawing is vectorized.

    The command receives `multi`, `threshold` (None or in (0, 1)), `blur` (px) and
    `classifier`, as `common.read_drawing` takes them. `prefix` (e.g. "Raster input: ")
    starts each help text on commands that also read SVG.
    """
    from vectorize.options import BLUR, THRESHOLD

    def text(words: str) -> str:
        return prefix + words if prefix else words[0].upper() + words[1:]

    decorators = [
        click.option("--multi", is_flag=True, help=text("multi-stroke drawing: keep every ink piece, "
                                                        "several strokes.")),
        click.option("--threshold", type=Number(THRESHOLD), default=None,
                     help=text(f"ink threshold, a gray level ({THRESHOLD.span()}) with paper = 1 after shading "
                               "correction; default: Li's method.")),
        click.option("--blur", type=Number(BLUR), default=0.0, show_default=True,
                     help=text(f"Gaussian blur sigma ({BLUR.span()}) before thresholding; helps "
                               "pencil scans and noisy photos.")),
        click.option("--classifier", type=click.Choice(["cnn", "geometric"]), default="cnn", show_default=True,
                     help=text("how crossings are told from touchings.")),
    ]
    def decorate(f: Callable) -> Callable:
        return _apply(f, decorators)

    return decorate(function) if function is not None else decorate


def placement_options(default_size: str | None = None) -> Callable:
    """--size, --width, --height, --rotate: how large the design is (mm) and its turn (degrees).

    The command receives `size`, `width`, `height` (mm or None) and `rotate`, as
    `job_options` takes them; `default_size` is only named in the help (the job applies it).
    """
    from fabrication.placement import ROTATE, PlacementOptions

    sides = ranges_of(PlacementOptions)
    shown = f" [default: {default_size}]" if default_size else ""
    return lambda function: _apply(function, [
        click.option("--size", type=Length(sides["size"]), default=None,
                     help=f"Longest side of the design, e.g. 90mm, 3.5in ({sides['size'].span()}){shown}."),
        click.option("--width", type=Length(sides["width"]), default=None,
                     help="Width of the design instead of --size."),
        click.option("--height", type=Length(sides["height"]), default=None,
                     help="Height of the design instead of --size."),
        click.option("--rotate", type=Number(ROTATE), default=0.0, show_default=True,
                     help=f"Degrees counter-clockwise, {ROTATE.span()}."),
    ])


def machine_options(*, port_required: bool = False, port_help: str | None = None) -> Callable:
    """--port, --baud, --profile: the GRBL machine a job is for or is sent to.

    The command receives `port` (str or None), `baud` (int) and `profile_path` (str or None).
    """
    return lambda function: _apply(function, [
        click.option("--port", type=Port(), required=port_required, default=None,
                     help=port_help or "Serial port (/dev/ttyUSB0, COM3) or sim:// for a dry run on the emulator."),
        click.option("--baud", type=BaudRate(), default=115200, show_default=True,
                     help="Serial baud rate (GRBL 1.1: 115200)."),
        click.option("--profile", "profile_path", type=InputFile(), default=None,
                     help="Laser profile TOML (bed, $30, rates, accelerations...); default: built-in 400x400 mm."),
    ])
