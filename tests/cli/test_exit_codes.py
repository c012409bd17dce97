"""The exit-code rule (docs/cli.md), tested over every command by one table.

2: the request was wrong before any work (bad option, missing input, an output folder that
does not exist, is read-only, immutable or special); 1: the work failed (disk full, a
device not there); 130: interrupted (Ctrl-C, SIGTERM, SIGHUP). Rows that need a real full
disk or a read-only file system run in a private mount namespace (tests/faults.py); the rest
through click's CliRunner, the same group and error mapping.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from fabrication.cli import COMMANDS, main
from tests.children import child_env
from tests.faults import locked_folder, run_with_mounts, tmpfs

SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="200" height="150"><path d="M 20 120 C 40 20, 80 20, '
       '100 75 S 160 130, 180 30" fill="none" stroke="black" stroke-width="3"/></svg>')
GCODE = "G21\nG90\nM4 S0\nG0 X5 Y5\nG1 X30 Y5 S600 F1500\nM5\n"

# Per command: a run that is fine but for the cases below ({in}: inputs, {dir}: the output
# folder of the case), a bad option, and a missing input.
COMMAND_LINES = {
    "vectorize": (["vectorize", "{in}/d.svg", "-o", "{dir}/a.svg"], ["--blur", "99"], "{in}/d.svg"),
    "embroider": (["embroider", "{in}/d.svg", "-o", "{dir}/a.pes"], ["--spm", "5"], "{in}/d.svg"),
    "laser": (["laser", "{in}/d.svg", "-o", "{dir}/a.gcode"], ["--passes", "0"], "{in}/d.svg"),
    "batch": (["batch", "{in}/d.svg", "-o", "{dir}/out"], ["--jobs", "0"], "{in}/d.svg"),
    "preview": (["preview", "{in}/d.svg", "-o", "{dir}/a.png"], ["--width", "1"], "{in}/d.svg"),
    "stream": (["stream", "{in}/job.gcode", "--port", "sim://"], ["--from-line", "0"], "{in}/job.gcode"),
    "studio": (["studio", "{in}/d.svg", "--no-browser", "--edits", "{dir}/e.json"], ["--port", "70000"],
               "{in}/d.svg"),
    "ports": (["ports", "--no-probe"], ["--probe", "--baud", "x"], None),
    "inkscape": (["inkscape", "install", "--dir", "{dir}/ext"], ["--user"], None),
    "emulator": (["emulator", "--log", "{dir}/x.log"], ["--speed", "0"], None),
    "train-classifier": (["train-classifier", "--out", "{dir}/m.onnx"], ["--epochs", "0"], None),
    "validate-classifier": (["validate-classifier", "--model", "{in}/m.onnx"], ["--count", "0"], "{in}/m.onnx"),
    "train-pass-scorer": (["train-pass-scorer", "--out", "{dir}/m.onnx"], ["--scenes", "1"], None),
}
WRITERS = [name for name, (argv, _, _) in COMMAND_LINES.items() if any("{dir}" in a for a in argv)]


def _rows():
    """(command, case, expected exit code) for every case a command can meet."""
    for name, (argv, _, source) in COMMAND_LINES.items():
        yield name, "bad option", 2
        if source is not None:
            yield name, "missing input", 2
        if name in WRITERS:
            for case in ("folder missing", "folder is a file", "immutable folder", "special folder (/proc)"):
                yield name, case, 2
    yield "stream", "port not there", 1


def test_the_table_covers_every_command():
    assert set(COMMAND_LINES) == set(COMMANDS)
    assert {name for name, _, _ in _rows()} == set(COMMANDS)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("in")
    (folder / "d.svg").write_text(SVG, encoding="utf-8")
    (folder / "job.gcode").write_text(GCODE, encoding="utf-8")
    (folder / "m.onnx").write_bytes(b"not used")
    return folder


def _argv(name: str, case: str, inputs: Path, folder: Path) -> list[str]:
    argv, bad, source = COMMAND_LINES[name]
    argv = list(argv)
    if case == "bad option":
        argv += bad
    elif case == "missing input":
        argv[argv.index(source)] = "{in}/missing" + Path(source).suffix
    elif case == "port not there":
        argv[argv.index("sim://")] = "/dev/ttyONESTROKE-NONE"
    return [a.replace("{in}", str(inputs)).replace("{dir}", str(folder)) for a in argv]


@pytest.mark.parametrize("name,case,code", list(_rows()), ids=[f"{n}:{c}" for n, c, _ in _rows()])
def test_exit_code(inputs, tmp_path, name, case, code):
    folder = {"folder missing": tmp_path / "missing", "folder is a file": tmp_path / "file",
              "special folder (/proc)": Path("/proc")}.get(case, tmp_path / "out")
    (tmp_path / "file").touch()
    argv = _argv(name, case, inputs, folder)
    if case == "immutable folder":
        with locked_folder(folder):
            result = CliRunner().invoke(main, argv)
    else:
        result = CliRunner().invoke(main, argv)
    assert result.exit_code == code, (argv, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "internal error" not in lines[0], result.stderr
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "out") == ["file"]
    if folder.name == "out" and folder.exists():
        assert list(folder.iterdir()) == []


def test_read_only_file_system_is_2_and_disk_full_is_1(inputs, tmp_path):
    """A real read-only tmpfs (EROFS) and a real full one (ENOSPC), every command that writes
    files: 2 before any work for the first, 1 for the second with nothing left on the disk."""
    ro, full = tmp_path / "ro", tmp_path / "full"
    ro.mkdir()
    full.mkdir()
    writers = [n for n in WRITERS if not n.startswith("train") and n not in ("studio", "emulator")]
    rows = [(_argv(name, "", inputs, ro), None) for name in WRITERS]
    rows += [(_argv(name, "", inputs, full), str(full)) for name in writers]
    # 4 kB: room for the first page of a file, not for an output and its temporary file
    results = run_with_mounts([tmpfs(ro, "64k", read_only=True), tmpfs(full, "4k"),
                               f"dd if=/dev/zero of={full}/ballast bs=4k count=1 2>/dev/null; true"], rows)
    for (argv, _), result in zip(rows, results):
        expected = 2 if str(ro) in " ".join(argv) else 1
        assert result["code"] == expected, (argv, result)
        lines = result["stderr"].strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), (argv, result["stderr"])
        if expected == 2:
            assert "read-only" in lines[0], lines[0]
        else:
            assert "the disk is full" in lines[0] and result["left"] in ([], ["ballast"]), (argv, result)


def _default_hangup() -> None:
    # As a command started from a terminal: under nohup the test runner's SIGHUP is ignored,
    # and the command rightly keeps an ignored signal ignored.
    signal.signal(signal.SIGHUP, signal.SIG_DFL)


def _child(*args: str) -> subprocess.Popen:
    code = "import sys; print('ready', flush=True); from fabrication.cli import main; main()"
    return subprocess.Popen([sys.executable, "-c", code, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=child_env(), preexec_fn=_default_hangup)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_are_an_interruption(tmp_path, signum):
    """130 and one line, as Ctrl-C; the temporary file of the output is removed."""
    from PIL import Image
    import numpy as np

    noise = tmp_path / "noise.png"
    Image.fromarray((np.random.default_rng(0).random((800, 800)) * 255).astype(np.uint8)).save(noise)
    out = tmp_path / "out"
    out.mkdir()
    child = _child("vectorize", str(noise), "-o", str(out / "a.svg"))
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.5)  # into the work (imports done or nearly)
    child.send_signal(signum)
    _, err = child.communicate(timeout=120)
    name = signal.Signals(signum).name
    assert (child.returncode, err.strip()) in ((130, f"interrupted ({name})"), (130, "interrupted")), err
    assert list(out.iterdir()) == []


def test_sigterm_stops_a_stream_as_ctrl_c_does(tmp_path):
    """A job on the emulator at machine pace, killed: halted (beam off), 130, the signal named."""
    job = tmp_path / "slow.gcode"
    job.write_text("G21\nG90\nM4 S0\nG1 X100 Y0 S300 F60\nG1 X0 Y0\nM5\n", encoding="utf-8")
    child = _child("stream", str(job), "--port", "sim://?speed=1")
    assert child.stdout.readline().strip() == "ready"
    time.sleep(4)  # connected and streaming (a 100 mm move at 60 mm/min takes 100 s)
    child.send_signal(signal.SIGTERM)
    _, err = child.communicate(timeout=60)
    assert child.returncode == 130 and "stopped by SIGTERM" in err and "Traceback" not in err, err
