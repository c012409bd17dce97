"""`sim://[?speed=N&profile=FILE.toml&rx=128&blocks=15&laser=1&travel=400x400&drop_hold=0]`: GRBL as a serial port.

The URL opens a `GrblEmulator` on a real pseudo-terminal and talks to it through an
ordinary `serial.Serial` on that pty, so the host side is the same code path as a USB
adapter. `speed` is the time scale (default 10: ten times faster than a real machine);
`profile` a laser profile TOML whose machine to emulate (bed, $30, rates, accelerations);
`drop_hold=N` loses the first N feed holds (`!`) on the way, to rehearse a stop.
"""

from __future__ import annotations

import urllib.parse

import serial
from serial.serialutil import PortNotOpenError, SerialBase, SerialException

from machines.emulator import TIME_SCALE, EmulatorOptions, Faults, GrblEmulator

DEFAULT_SPEED = 10.0


# Integer parameters: (lowest, highest). GRBL boards have RX buffers of 64-1024 bytes and
# planners of 8-32 blocks; the emulator takes any buffer from 1 byte (to rehearse a line
# that cannot fit: the sender refuses it by name) and 2-256 blocks.
_INTEGERS = {"rx": (1, 65536), "blocks": (2, 256), "drop_hold": (0, 1000), "laser": (0, 1)}


def parse_sim_url(url: str) -> EmulatorOptions:
    """Emulator options from a `sim://` URL; raises ValueError naming a bad parameter or value
    (numbers in ASCII decimal, each within its range)."""
    from onestroke.errors import InputError
    from onestroke.units import parse_integer, parse_number, parse_size_pair

    parts = urllib.parse.urlsplit(url)
    if parts.scheme != "sim":
        raise ValueError(f"expected a sim:// URL, got {url!r}")
    speed, numbers, settings = DEFAULT_SPEED, {"rx": 128, "blocks": 15}, {}
    for key, values in urllib.parse.parse_qs(parts.query, keep_blank_values=True).items():
        value = values[-1]
        what = f"sim:// parameter {key!r}"
        try:
            if key == "speed":
                speed = TIME_SCALE.named(what).check(parse_number(value, what=what), shown=repr(value))
            elif key in _INTEGERS:
                low, high = _INTEGERS[key]
                numbers[key] = parse_integer(value, what=what)
                if not low <= numbers[key] <= high:
                    raise ValueError(f"bad value {value!r} for {what}: give a whole number from {low} to {high}")
            elif key == "profile":
                from machines.grbl_settings import settings_from_profile
                from machines.laser_profile import load_laser_profile

                settings = {**settings_from_profile(load_laser_profile(value)), **settings}
            elif key == "travel":
                settings[130], settings[131] = parse_size_pair(value, what=what)
            else:
                raise ValueError(f"unknown sim:// parameter {key!r}; use speed, rx, blocks, laser, travel, "
                                 "profile, drop_hold")
        except InputError as error:
            if key == "travel":
                raise ValueError(f"bad value {value!r} for {what}: give the bed as WxH in mm, e.g. 400x400") from None
            raise ValueError(str(error)) from None
    if "laser" in numbers:
        settings[32] = float(numbers["laser"])
    faults = {"drop_hold": numbers["drop_hold"]} if "drop_hold" in numbers else {}
    return EmulatorOptions(time_scale=speed, rx_buffer=numbers["rx"], planner_blocks=numbers["blocks"],
                           settings=settings, faults=Faults(**faults))


class Serial(SerialBase):
    """A pyserial port whose far end is an in-process GRBL emulator on a pty."""

    emulator: GrblEmulator | None = None

    def open(self) -> None:
        if self._port is None:
            raise SerialException("port must be configured before it can be used")
        if self.is_open:
            raise SerialException("port already open")
        try:
            options = parse_sim_url(self._port)
        except ValueError as error:
            raise SerialException(str(error)) from None
        self.time_scale = options.time_scale
        self.emulator = GrblEmulator(options)
        device = self.emulator.start_pty()
        self._tty = serial.Serial(device, baudrate=self._baudrate, timeout=self._timeout,
                                  write_timeout=self._write_timeout)
        self.is_open = True

    def close(self) -> None:
        if getattr(self, "_tty", None) is not None:
            self._tty.close()
            self._tty = None
        if self.emulator is not None:
            self.emulator.stop()
        self.is_open = False

    def _reconfigure_port(self) -> None:
        if getattr(self, "_tty", None) is not None:
            self._tty.timeout = self._timeout
            self._tty.write_timeout = self._write_timeout

    def _check(self):
        if not self.is_open or self._tty is None:
            raise PortNotOpenError()
        return self._tty

    @property
    def in_waiting(self) -> int:
        return self._check().in_waiting

    def read(self, size: int = 1) -> bytes:
        return self._check().read(size)

    def write(self, data) -> int | None:
        return self._check().write(data)

    def flush(self) -> None:
        self._check().flush()

    def reset_input_buffer(self) -> None:
        self._check().reset_input_buffer()

    def reset_output_buffer(self) -> None:
        self._check().reset_output_buffer()

    def fileno(self) -> int:
        return self._check().fileno()
