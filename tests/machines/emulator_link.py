"""The GRBL emulator on a real pseudo-terminal, driven with plain pyserial (`Link`), and
`onestroke stream` in a child process; the fixtures that make them are in
tests/machines/conftest.py."""

import os
import signal
import subprocess
import sys
import time

import serial

from machines.emulator import EmulatorOptions, GrblEmulator


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


def answered(line):
    return line == "ok" or line.startswith("error:")


def hear_ctrl_c():
    """In a child about to exec: take Ctrl-C (SIGINT) again. A shell starts background
    jobs with SIGINT ignored, and a child inherits that, so a test suite run in the
    background would otherwise send its Ctrl-C to a process that cannot hear it."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def stream_in_child(path, port: str) -> subprocess.Popen:
    """`onestroke stream PATH --port PORT` in a child process (stderr piped, hears Ctrl-C)."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.Popen([sys.executable, "-c", "from fabrication.cli import main; main()", "stream",
                             str(path), "--port", port], stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=hear_ctrl_c)
