"""Port opening and discovery against the emulator on a pty: GRBL probe, busy, missing, permissions."""

import errno

import pytest

from machines.emulator import EmulatorOptions, Faults, GrblEmulator
from machines.ports import _explain, open_port, probe_grbl
from onestroke.errors import MachineError


@pytest.fixture
def emu():
    emulator = GrblEmulator(EmulatorOptions(time_scale=20.0))
    emulator.start_pty()
    yield emulator
    emulator.stop()


def test_probe_finds_grbl_by_its_welcome(emu):
    assert probe_grbl(emu.device, wait=2.0) == "1.1h"


def test_probe_of_a_silent_device_says_none():
    silent = GrblEmulator(EmulatorOptions(faults=Faults(silent=True)))
    try:
        assert probe_grbl(silent.start_pty(), wait=0.5) is None
    finally:
        silent.stop()


def test_busy_port_is_explained(emu):
    first = open_port(emu.device)
    try:
        with pytest.raises(MachineError, match="busy: another program"):
            open_port(emu.device)
    finally:
        first.close()


def test_missing_port_and_permission_messages():
    with pytest.raises(MachineError, match="does not exist"):
        open_port("/dev/ttyUSB-onestroke-missing")
    # Root bypasses file permissions, so the EACCES wording is checked on the error itself.
    message = _explain("/dev/ttyUSB0", PermissionError(errno.EACCES, "Permission denied"))
    assert "dialout" in message and "usermod" in message
    assert "brltty" in message
