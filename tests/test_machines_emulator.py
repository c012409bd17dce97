"""The GRBL emulator on a real pseudo-terminal, driven with plain pyserial."""

import time

import pytest
import serial

from machines.emulator import EmulatorOptions, GrblEmulator
from machines.ports import open_port
from onestroke.errors import MachineError


class Link:
    """A raw pyserial connection to an emulator, reading whole lines."""

    def __init__(self, **options):
        self.emu = GrblEmulator(EmulatorOptions(**options))
        self.port = serial.Serial(self.emu.start_pty(), 115200, timeout=0.05)
        self.buffer = b""

    def lines(self, wait=0.3, until=None):
        out, deadline = [], time.monotonic() + wait
        while time.monotonic() < deadline:
            self.buffer += self.port.read(self.port.in_waiting or 1)
            while b"\n" in self.buffer:
                line, _, self.buffer = self.buffer.partition(b"\n")
                line = line.strip()
                if line:
                    out.append(line.decode("latin-1"))
                    if until is not None and until(out[-1]):
                        return out
        return out

    def send(self, data, until=None, wait=2.0):
        self.port.write(data)
        return self.lines(wait, until)

    def close(self):
        self.port.close()
        self.emu.stop()


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


def answered(line):
    return line == "ok" or line.startswith("error:")


def test_welcome_info_settings_and_modal_state(link):
    grbl = link()
    assert grbl.send(b"\x18", until=lambda l: l.startswith("Grbl")) == ["Grbl 1.1h ['$' for help]"]
    assert grbl.send(b"$I\n", until=answered) == ["[VER:1.1h.20190825:]", "[OPT:V,15,128]", "ok"]
    settings = grbl.send(b"$$\n", until=answered)
    assert "$30=1000" in settings and "$32=1" in settings and "$110=6000.000" in settings
    assert grbl.send(b"$G\n", until=answered)[0].startswith("[GC:G0 G54 G17 G21 G90 G94 M5")
    assert grbl.send(b"$Q\n", until=answered) == ["error:3"]


def test_errors_unsupported_too_long_feed_undefined(link):
    grbl = link()
    assert grbl.send(b"G5 X1\n", until=answered) == ["error:20"]
    assert grbl.send(b"G1X" + b"1" * 80 + b"\n", until=answered) == ["error:11"]
    assert grbl.send(b"G1 X1 (a comment does not count) ; nor this\n", until=answered) == ["error:22"]
    # CR LF is two line ends for GRBL: two answers.
    assert grbl.send(b"G21\r\n", until=None, wait=0.3) == ["ok", "ok"]
    assert grbl.emu.executed == ["G21"]


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


def test_realtime_status_hold_resume_and_reset_alarm(link):
    grbl = link(time_scale=5.0)
    assert grbl.send(b"G1X100F3000\n", until=answered) == ["ok"]
    time.sleep(0.05)
    status = grbl.send(b"?", until=lambda l: l.startswith("<"))[-1]
    assert status.startswith("<Run|MPos:") and "FS:" in status
    grbl.send(b"!", wait=0.02)
    hold = grbl.send(b"?", until=lambda l: l.startswith("<"))[-1]
    assert hold.startswith("<Hold:")
    time.sleep(0.1)
    assert grbl.send(b"?", until=lambda l: l.startswith("<"))[-1].startswith("<Hold:0")
    stopped_at = grbl.emu.position[0]
    assert 0 < stopped_at < 100
    grbl.send(b"~", wait=0.05)
    assert grbl.send(b"?", until=lambda l: l.startswith("<"))[-1].startswith("<Run")
    replies = grbl.send(b"\x18", until=lambda l: "unlock" in l)  # reset while moving
    assert replies[:2] == ["ALARM:3", "Grbl 1.1h ['$' for help]"] and "unlock" in replies[-1]
    assert grbl.send(b"G0X0\n", until=answered) == ["error:9"]
    assert grbl.send(b"$X\n", until=answered) == ["[MSG:Caution: Unlocked]", "ok"]
    assert not grbl.emu.beam_on


def test_soft_limit_alarm_and_check_mode(link):
    grbl = link(settings={22: 1, 20: 1, 130: 100, 131: 100})
    assert "unlock" in grbl.send(b"\x18", until=lambda l: "unlock" in l)[-1]  # homing enabled: boots locked
    assert grbl.send(b"$H\n", until=answered) == ["ok"]
    assert grbl.send(b"G0X150\n", until=lambda l: "Reset" in l) == ["ALARM:2", "[MSG:Reset to continue]"]
    assert grbl.send(b"\x18", until=lambda l: "unlock" in l)[-1] == "[MSG:'$H'|'$X' to unlock]"
    assert grbl.send(b"$X\n", until=answered)[-1] == "ok"
    assert grbl.send(b"$C\n", until=answered) == ["[MSG:Enabled]", "ok"]
    assert grbl.send(b"G1X10F100\n", until=answered) == ["ok"]
    assert grbl.send(b"G5\n", until=answered) == ["error:20"]
    assert grbl.emu.stats().blocks_executed == 0  # check mode parses, never moves
    assert grbl.send(b"$C\n", until=lambda l: l.startswith("Grbl"))[-1].startswith("Grbl")


def test_eeprom_write_loses_bytes_sent_meanwhile(link):
    grbl = link(time_scale=1.0)
    # Streaming on right after an EEPROM write is what send-response for such lines avoids.
    grbl.port.write(b"$110=5000\n" + b"G21\n" * 30)
    replies = grbl.lines(0.5)
    assert replies[0] == "ok" and grbl.emu.stats().eeprom_lost_bytes > 0
    assert len(grbl.emu.executed) < 30
    assert grbl.emu.settings[110] == 5000


def test_planner_timing_single_move_and_limited_time(link):
    grbl = link(time_scale=10.0)
    start = time.monotonic()
    grbl.port.write(b"G1X100F3000\nG4P0\n")
    replies = grbl.lines(3.0, until=lambda l: grbl.emu.stats().blocks_executed == 1)
    wall = time.monotonic() - start
    stats = grbl.emu.stats()
    # 100 mm at 50 mm/s, a = 500 mm/s^2: 2.1 s of machine time, 0.21 s at 10x.
    assert stats.planner_limited_time == pytest.approx(2.1, rel=1e-6)
    assert stats.motion_time == pytest.approx(2.1, rel=0.05)
    assert 0.2 < wall < 0.6
    assert replies


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
