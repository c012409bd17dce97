"""Serial port discovery and opening, with plain-language errors (dialout group, busy ports).

`open_port` accepts device paths and pyserial URLs, including onestroke's own `sim://`
(a GRBL emulator for dry runs; see `machines.sim_url`).
"""

from __future__ import annotations

import errno
import os
import time
from dataclasses import dataclass

import serial
import serial.tools.list_ports

from machines.grbl_protocol import SOFT_RESET, Welcome, parse_reply
from onestroke.errors import MachineError

if "machines.sim_url" not in serial.protocol_handler_packages:
    serial.protocol_handler_packages.append("machines.sim_url")

DIALOUT_HINT = ("add yourself to the 'dialout' group (sudo usermod -aG dialout $USER), then log out and in "
                "again; on some distributions also remove brltty, which grabs CH340/CP210x adapters")


@dataclass(frozen=True)
class PortInfo:
    """One serial port: device path, description, USB ids (may be None) and GRBL probe result."""

    device: str
    description: str
    hwid: str
    vid: int | None = None
    pid: int | None = None
    grbl_version: str | None = None
    problem: str | None = None


def _explain(device: str, error: Exception) -> str:
    """Turn a pyserial/OS error on `device` into one sentence saying what to do."""
    number = getattr(error, "errno", None)
    text = str(error)
    if number == errno.EACCES or "Permission denied" in text:
        return f"permission denied on {device}: {DIALOUT_HINT}"
    if number in (errno.EBUSY, errno.EAGAIN) or "exclusively lock" in text or "Device or resource busy" in text:
        return (f"{device} is busy: another program has it open (a sender like LaserGRBL/UGS, a serial "
                "monitor, ModemManager or brltty); close it and retry")
    if number == errno.ENOENT or "No such file" in text or "could not open port" in text and "2]" in text:
        return f"{device} does not exist; run 'onestroke ports' to list serial ports"
    return f"cannot open {device}: {text}"


def open_port(port: str, *, baud: int = 115200, timeout: float = 0.05) -> serial.SerialBase:
    """Open `port` (device path or URL such as `sim://`) 8-N-1 in binary mode.

    The port is locked for exclusive use so that two senders never share one machine.
    Raises MachineError with a one-line explanation (permissions, busy, missing).
    """
    try:
        if "://" in port:
            return serial.serial_for_url(port, baudrate=baud, timeout=timeout, write_timeout=2.0)
        return serial.Serial(port, baudrate=baud, timeout=timeout, write_timeout=2.0, exclusive=True)
    except (serial.SerialException, OSError, ValueError) as error:
        raise MachineError(_explain(port, error)) from None


def probe_grbl(port: str, *, baud: int = 115200, wait: float = 2.5) -> str | None:
    """Open `port`, soft-reset and wait up to `wait` s for GRBL's welcome; its version or None.

    Many Arduino boards reset when the port opens and their bootloader needs ~1-2 s, so
    `wait` covers that. Raises MachineError if the port cannot be opened.
    """
    handle = open_port(port, baud=baud)
    try:
        handle.reset_input_buffer()
        handle.write(SOFT_RESET)
        deadline = time.monotonic() + wait
        buffer = b""
        while time.monotonic() < deadline:
            buffer += handle.read(handle.in_waiting or 1)
            while b"\n" in buffer:
                line, _, buffer = buffer.partition(b"\n")
                reply = parse_reply(line)
                if isinstance(reply, Welcome):
                    return reply.version
        return None
    except (serial.SerialException, OSError) as error:
        raise MachineError(_explain(port, error)) from None
    finally:
        handle.close()


def list_ports(*, probe: bool = False, baud: int = 115200, wait: float = 2.5) -> list[PortInfo]:
    """Serial ports of this computer, optionally probed for GRBL (each probe takes up to `wait` s)."""
    found = []
    for entry in sorted(serial.tools.list_ports.comports(), key=lambda p: p.device):
        version, problem = None, None
        if probe:
            try:
                version = probe_grbl(entry.device, baud=baud, wait=wait)
            except MachineError as error:
                problem = str(error)
        elif not os.access(entry.device, os.R_OK | os.W_OK):
            problem = f"permission denied on {entry.device}: {DIALOUT_HINT}"
        found.append(PortInfo(entry.device, entry.description or "n/a", entry.hwid or "n/a",
                              entry.vid, entry.pid, version, problem))
    return found
