"""Fixtures of the emulator and streaming tests: emulators on real pseudo-terminals, stopped
after each test."""

import pytest

from machines.emulator import EmulatorOptions, GrblEmulator
from tests.machines.emulator_link import Link


@pytest.fixture
def link():
    made = []

    def make(**options):
        options.setdefault("time_scale", 50.0)
        made.append(Link(**options))
        made[-1].lines(0.2)  # boot welcome
        return made[-1]

    yield make
    for item in made:
        item.close()


@pytest.fixture
def emulator():
    """make(**EmulatorOptions) -> a started emulator on a pty (default 40x), stopped afterwards."""
    made = []

    def make(**options):
        options.setdefault("time_scale", 40.0)
        emu = GrblEmulator(EmulatorOptions(**options))
        emu.start_pty()
        made.append(emu)
        return emu

    yield make
    for emu in made:
        emu.stop()
