"""Emulator transport: the wire, the serial interrupt's RX buffer, the pty behind `sim://`."""

import time

import pytest
from machines.ports import open_port
from onestroke.errors import MachineError


def test_rx_overflow_drops_bytes_like_the_firmware(link):
    grbl = link(time_scale=1.0)
    # Fill the planner with slow moves, then blast 40 lines without waiting for answers.
    lines = [b"G1X%dY0F60\n" % (i % 2 * 5) for i in range(40)]
    grbl.port.write(b"".join(lines))
    time.sleep(1.0)
    stats = grbl.emu.stats()
    assert stats.rx_overflow_bytes > 0 and stats.max_rx_used == 128
    grbl.port.write(b"\x18")
    time.sleep(0.2)


def test_eeprom_write_loses_bytes_sent_meanwhile(link):
    grbl = link(time_scale=1.0)
    # Streaming on right after an EEPROM write is what send-response for such lines avoids.
    grbl.port.write(b"$110=5000\n" + b"G21\n" * 30)
    replies = grbl.lines(0.5)
    assert replies[0] == "ok" and grbl.emu.stats().eeprom_lost_bytes > 0
    assert len(grbl.emu.executed) < 30
    assert grbl.emu.settings[110] == 5000


def test_sim_url_opens_an_emulator_through_pyserial():
    port = open_port("sim://?speed=20&travel=300x200")
    try:
        port.write(b"\x18")
        time.sleep(0.2)
        port.write(b"$$\n")
        time.sleep(0.3)
        text = port.read(4000).decode()
        assert "Grbl 1.1h" in text and "$130=300.000" in text and "$131=200.000" in text
        assert port.emulator is not None and port.time_scale == 20.0
    finally:
        port.close()


def test_sim_url_emulates_a_laser_profile(tmp_path):
    profile = tmp_path / "small.toml"
    profile.write_text('name = "small"\n[bed]\nsize = "300x200mm"\n[laser]\nmax_power = 255\n')
    port = open_port(f"sim://?speed=20&profile={profile}")
    try:
        assert port.emulator.settings[30] == 255 and port.emulator.settings[130] == 300
    finally:
        port.close()
    with pytest.raises(MachineError, match="does not exist"):
        open_port(f"sim://?profile={tmp_path / 'missing.toml'}")
