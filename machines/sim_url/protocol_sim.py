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

from machines.emulator import EmulatorOptions, Faults, GrblEmulator

DEFAULT_SPEED = 10.0


def parse_sim_url(url: str) -> EmulatorOptions:
    """Emulator options from a `sim://` URL; raises ValueError naming a bad parameter."""
    parts = urllib.parse.urlsplit(url)
    if parts.scheme != "sim":
        raise ValueError(f"expected a sim:// URL, got {url!r}")
    speed, rx, blocks, settings, faults = DEFAULT_SPEED, 128, 15, {}, {}
    for key, values in urllib.parse.parse_qs(parts.query, keep_blank_values=True).items():
        value = values[-1]
        try:
            if key == "speed":
                speed = float(value)
                if not speed > 0:
                    raise ValueError
            elif key == "rx":
                rx = int(value)
            elif key == "blocks":
                blocks = int(value)
            elif key == "drop_hold":
                faults["drop_hold"] = int(value)
            elif key == "laser":
                settings[32] = float(int(value))
            elif key == "profile":
                from machines.grbl_settings import settings_from_profile
                from machines.laser_profile import load_laser_profile

                try:
                    settings = {**settings_from_profile(load_laser_profile(value)), **settings}
                except Exception as error:  # noqa: BLE001 - InputError and friends, reported as one line
                    raise ValueError(f"sim:// profile: {error}") from None
            elif key == "travel":
                width, height = (float(v) for v in value.lower().split("x"))
                settings[130], settings[131] = width, height
            else:
                raise KeyError(key)
        except KeyError:
            raise ValueError(f"unknown sim:// parameter {key!r}; use speed, rx, blocks, laser, travel, "
                             "profile, drop_hold") from None
        except ValueError as error:
            if str(error).startswith("sim://"):
                raise
            raise ValueError(f"bad value {value!r} for sim:// parameter {key!r}") from None
    return EmulatorOptions(time_scale=speed, rx_buffer=rx, planner_blocks=blocks, settings=settings,
                           faults=Faults(**faults))


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
