"""Issue 14, item by item: a table of command lines with the exit code and a fragment of the
one-line message each must give. Every row failed before the change (a silent overwrite, a
traceback, a run away, a misleading message) and passes after it.

Runs through click's CliRunner (faithful here: the same group, the same error mapping);
only Ctrl-C and file-size limits need a real process.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image, ImageDraw

from benchmarks.large_inputs import many_paths_svg
from fabrication.cli import main
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke
from vectorize.svg_write import write_drawing
from tests.children import child_env

PATH = '<path d="M 20 120 C 40 20, 80 20, 100 75 S 160 130, 180 30" fill="none" stroke="black" stroke-width="3"/>'


def svg(body: str = PATH, root: str = 'xmlns="http://www.w3.org/2000/svg"', wrap: str | None = None) -> str:
    text = f'<svg {root} width="200" height="150">{body}</svg>'
    return wrap.format(text) if wrap else text


FILES = {
    "d.svg": svg(),
    "https.svg": svg(root='xmlns="https://www.w3.org/2000/svg"'),
    "slash.svg": svg(root='xmlns="http://www.w3.org/2000/svg/"'),
    "xhtml.svg": svg(wrap='<html xmlns="http://www.w3.org/1999/xhtml"><body>{}</body></html>'),
    "hidden.svg": svg(root='xmlns="http://www.w3.org/2000/svg" style="display:none"'),
    "huge-circle.svg": svg('<circle id="sun" cx="50" cy="50" r="1e300" fill="black"/>'),
    "e30.svg": svg('<path d="M1e30 0 L 2e30 5e29 L 3e30 0" stroke="black" fill="none"/>'),
    "job.gcode": "G21\nG90\nM4 S0\nG0 X5 Y5\nG1 X30 Y5 S600 F1500\nG1 X30 Y30\nM5\n",
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    base = tmp_path_factory.mktemp("refusals")
    for name, text in FILES.items():
        (base / name).write_text(text, encoding="utf-8")
    (base / "latin1.gcode").write_bytes(b"; Tiefe 2\xb0 (Latin-1 degree sign)\n" + FILES["job.gcode"].encode())
    (base / "garbage.pes").write_bytes(np.random.default_rng(4).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    noise = (np.random.default_rng(0).random((400, 400)) * 255).astype(np.uint8)
    Image.fromarray(noise).save(base / "noise.png")
    Image.fromarray(noise).save(base / "2-medial-axis.png")  # the name of a --debug stage image
    (base / "garbage.jef").write_bytes(np.random.default_rng(5).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    (base / "far.json").write_text(
        '{"format": "onestroke-drawing", "width": 10, "height": 10, "unit": "px", '
        '"strokes": [[[[0, 0], [1, 1], [2, 2], [1e300, 5e299]]]]}', encoding="utf-8")
    os.symlink(base / "d.svg", base / "link.svg")
    os.link(base / "d.svg", base / "hard.svg")
    (base / "dir.pes").mkdir()
    os.symlink(base / "x.gcode", base / "x.frame.gcode")  # laser -o x.gcode --frame writes it: the same file
    (base / "many.svg").write_text(many_paths_svg(300), encoding="utf-8")
    return base


# (item, arguments, exit code, fragment of stderr); {in} is the input folder, {out} a fresh one.
TABLE = [
    # 1. an output never replaces an input or another output
    ("1", ["vectorize", "{in}/d.svg", "-o", "{in}/d.svg"], 2, "same file as the input"),
    ("1", ["vectorize", "{in}/d.svg", "-o", "{in}/link.svg"], 2, "same file as the input"),
    ("1", ["vectorize", "{in}/d.svg", "-o", "{in}/hard.svg"], 2, "same file as the input"),
    ("1", ["embroider", "{in}/d.svg", "-o", "{out}/d.pes", "--preview", "{in}/d.svg"], 2, "--preview"),
    ("1", ["preview", "{in}/d.svg", "-o", "{in}/d.svg"], 2, "same file as the input"),
    ("1", ["laser", "{in}/d.svg", "-o", "{in}/x.gcode", "--frame"], 2, "frame file"),
    ("1", ["vectorize", "{in}/2-medial-axis.png", "-o", "{out}/a.svg", "--debug", "{in}"], 2, "--debug image"),
    ("1", ["studio", "{in}/d.svg", "--edits", "{in}/d.svg", "--no-browser"], 2, "same file as the input"),
    # 2. SVG spellings read, absurd coordinates refused naming the element
    ("2", ["vectorize", "{in}/https.svg", "-o", "{out}/a.svg"], 0, ""),
    ("2", ["vectorize", "{in}/slash.svg", "-o", "{out}/a.svg"], 0, ""),
    ("2", ["vectorize", "{in}/xhtml.svg", "-o", "{out}/a.svg"], 0, ""),
    ("2", ["vectorize", "{in}/hidden.svg", "-o", "{out}/a.svg"], 2, "hidden"),
    ("2", ["vectorize", "{in}/huge-circle.svg", "-o", "{out}/a.svg"], 2, "<circle id='sun'>"),
    ("2", ["vectorize", "{in}/e30.svg", "-o", "{out}/a.svg"], 2, "beyond the limit"),
    ("2", ["preview", "{in}/far.json", "-o", "{out}/a.png"], 2, "beyond the limit"),
    # 3. options that would run away are refused before any work
    ("3", ["embroider", "{in}/d.svg", "-o", "{out}/a.pes", "--stitch-length", "0.0001mm"], 2, "--stitch-length"),
    ("3", ["embroider", "{in}/d.svg", "-o", "{out}/a.pes", "--stitch-length", "0.2mm"], 2, "--min-stitch"),
    ("3", ["laser", "{in}/d.svg", "-o", "{out}/a.gcode", "--passes", "1000000"], 2, "--passes"),
    ("3", ["laser", "{in}/d.svg", "-o", "{out}/a.gcode", "--blur", "1e9"], 2, "--blur"),
    ("3", ["vectorize", "{in}/d.svg", "-o", "{out}/a.svg", "--blur", "1e9"], 2, "--blur"),
    ("3", ["laser", "{in}/d.svg", "-o", "{out}/a.gcode", "--feed", "0.0001mm/min"], 2, "--feed"),
    ("3", ["laser", "{in}/noise.png", "-o", "{out}/a.gcode"], 2, "--blur"),
    # 4. OS errors: one line; a folder that cannot take files is found before any work (issue 28: exit 2)
    ("4", ["vectorize", "{in}/d.svg", "-o", "/proc/onestroke-test.svg"], 2, "cannot write"),
    ("4", ["vectorize", "{in}/d.svg", "-o", "/sys/onestroke-test.svg"], 2, "cannot write"),
    # 5. messages name the real problem and an option the command has
    ("5", ["embroider", "{in}/dir.pes", "-o", "{out}/a.pes"], 2, "is a directory"),
    ("5", ["preview", "{in}/dir.pes", "-o", "{out}/a.png"], 2, "is a directory"),
    ("5", ["vectorize", "{in}/d.svg", "-o", "/etc/hostname/x.svg"], 2, "is a file, not a folder"),
    ("5", ["embroider", "{in}/d.svg", "-o", "{out}/a.pes", "--rotate", "nan"], 2, "--rotate 'nan' is not a number"),
    ("5", ["embroider", "{in}/d.svg", "-o", "{out}/a.pes", "--hoop", "9" * 1000], 2, " ... "),
    ("5", ["vectorize", "{in}/noise.png", "-o", "{out}/a.svg", "--threshold", "0.4"], 2, "with that threshold"),
    ("5", ["preview", "{in}/garbage.pes", "-o", "{out}/a.png"], 2, "not a valid .pes file (damaged"),
    ("5", ["preview", "{in}/garbage.jef", "-o", "{out}/a.png"], 2, "not a valid .jef file (damaged"),
    ("5", ["stream", "{in}/job.gcode", "--port", ""], 2, "--port is empty"),
    ("5", ["stream", "{in}/job.gcode", "--port", "sim://foo"], 2, "sim://?speed"),
    ("5", ["stream", "{in}/job.gcode", "--port", "sim://", "--check", "--frame"], 2, "cannot be combined"),
    ("5", ["laser", "{in}/d.svg", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "0"], 2, "--baud 0"),
    ("5", ["preview", "{in}/latin1.gcode", "-o", "{out}/a.png"], 0, ""),
    ("5", ["vectorize", "{in}/d.svg", "-o", "{out}/a.svg", "--classifier", "x"], 2, "vectorize --help'"),
]


@pytest.mark.parametrize("item,args,code,fragment", TABLE,
                         ids=[f"{i}:{' '.join(a[:1] + a[3:])[:60]}" for i, a, _, _ in TABLE])
def test_invocation(folder, tmp_path, item, args, code, fragment):
    argv = [a.replace("{in}", str(folder)).replace("{out}", str(tmp_path)) for a in args]
    before = {p.name: p.lstat().st_mtime_ns for p in folder.iterdir()}
    result = CliRunner().invoke(main, argv)
    assert result.exit_code == code, (result.exit_code, result.output)
    assert "Traceback" not in result.output and "internal error" not in result.stderr
    if code:
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
        assert fragment in lines[0] and len(lines[0]) <= 520, lines[0]
        assert list(tmp_path.iterdir()) == []  # nothing written, not even a partial file
    assert {p.name: p.lstat().st_mtime_ns for p in folder.iterdir()} == before  # inputs untouched


SHARED = [("--size", "0.01mm", "--size '0.01mm' must be from 0.1 mm to 10000 mm"),
          ("--blur", "30", "--blur 30 must be from 0 px to 25 px"),
          ("--threshold", "2", "--threshold 2 must be above 0 to below 1"),
          ("--rotate", "400", "--rotate 400 must be from -360 degrees to 360 degrees")]
COMMANDS = {"vectorize": ["-o", "{out}/a.svg"], "embroider": ["-o", "{out}/a.pes"],
            "laser": ["-o", "{out}/a.gcode"], "batch": ["-o", "{out}/b", "--to", "svg,pes,gcode"]}


@pytest.mark.parametrize("option,value,message", SHARED, ids=[o for o, _, _ in SHARED])
def test_shared_options_are_spelled_and_checked_the_same_on_every_command(folder, tmp_path, option, value, message):
    """What to build: one declaration per option group, so every command that takes an
    option refuses the same bad value with the same line, before any work."""
    lines = {}
    for command, rest in COMMANDS.items():
        if option not in CliRunner().invoke(main, [command, "--help"]).output:
            continue
        argv = [command, str(folder / "d.svg"), *[a.replace("{out}", str(tmp_path)) for a in rest], option, value]
        result = CliRunner().invoke(main, argv)
        lines[command] = (result.exit_code, result.stderr.strip())
    assert len(lines) >= 3 and set(lines.values()) == {(2, f"error: {message}")}, lines
    assert list(tmp_path.iterdir()) == []


# 6. long work shows progress: (arguments, a progress line that must appear when stderr is
# not a terminal and plain lines are asked for). ONESTROKE_PROGRESS_SECONDS=0 prints every
# report, so a small input shows what a large one shows over minutes; unset, a log or a pipe
# gets only the final summary (a terminal gets the bar: test_progress_bar_on_a_terminal).
PROGRESS = [
    (["vectorize", "{in}/many.svg", "-o", "{out}/a.svg"], "vectorizing many.svg: reading shapes: 100 %"),
    (["embroider", "{in}/many.svg", "-o", "{out}/a.pes", "--size", "180mm", "--hoop", "200x200"],
     "planning the stitches: stitching: 100 % (300/300 strokes)"),
    (["laser", "{in}/many.svg", "-o", "{out}/a.gcode", "--size", "180mm"],
     "planning the toolpath: reading G-code: 100 %"),
    (["laser", "{in}/many.svg", "-o", "{out}/a.gcode", "--size", "180mm"],
     "planning the toolpath: flattening: 100 % (300/300 strokes)"),
    (["preview", "{in}/many.svg", "-o", "{out}/a.png"], "reading many.svg: parsing: 100 %"),
    (["preview", "{in}/job.gcode", "-o", "{out}/a.png"], "drawing job.gcode: reading G-code: 100 % (7/7 lines)"),
]


def _percentages(stderr: str) -> dict[str, list[int]]:
    """Percent figures of the plain progress lines, by step and stage."""
    import re

    found: dict[str, list[int]] = {}
    for line in stderr.splitlines():
        match = re.match(r"(.+): (\d+) % \(", line)
        if match:
            found.setdefault(match.group(1), []).append(int(match.group(2)))
    return found


@pytest.mark.parametrize("args,line", PROGRESS, ids=[f"6:{a[0]} {a[1][5:]}" for a, _ in PROGRESS])
def test_progress_lines_when_not_on_a_terminal(folder, tmp_path, monkeypatch, args, line):
    argv = [a.replace("{in}", str(folder)).replace("{out}", str(tmp_path)) for a in args]
    monkeypatch.setenv("ONESTROKE_PROGRESS_SECONDS", "0")
    result = CliRunner().invoke(main, argv)
    assert result.exit_code == 0, result.output
    assert line in result.stderr, result.stderr
    stages = _percentages(result.stderr)
    assert stages and all(p == sorted(p) and p[-1] == 100 for p in stages.values()), stages
    # a step shorter than the pace asked for prints no line (here: one line a minute at most)
    monkeypatch.setenv("ONESTROKE_PROGRESS_SECONDS", "60")
    quiet = CliRunner().invoke(main, argv)
    assert quiet.exit_code == 0 and _percentages(quiet.stderr) == {}, quiet.stderr
    # not asked for: quiet but for the final summary
    monkeypatch.delenv("ONESTROKE_PROGRESS_SECONDS")
    quiet = CliRunner().invoke(main, argv)
    assert quiet.exit_code == 0 and _percentages(quiet.stderr) == {}, quiet.stderr


def test_progress_through_a_real_pipe(folder, tmp_path):
    """A real process with stderr piped: plain lines with percentages, the summary on stdout."""
    env = child_env(ONESTROKE_PROGRESS_SECONDS="0")
    done = subprocess.run([sys.executable, "-m", "fabrication.cli", "embroider", str(folder / "many.svg"), "-o",
                           str(tmp_path / "a.pes"), "--size", "180mm", "--hoop", "200x200"],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    stages = _percentages(done.stderr)
    assert stages["planning the stitches: stitching"][-1] == 100 and stages["reading many.svg: parsing"][-1] == 100
    assert "\x1b[" not in done.stderr  # no terminal codes in a pipe
    assert done.stdout.startswith(f"wrote {tmp_path / 'a.pes'}")


def test_progress_bar_on_a_terminal(folder, tmp_path):
    """On a real terminal (a pty) the step shows rich's bar with a percentage, then only the
    summary stays."""
    import pty
    import select

    env = {k: v for k, v in child_env(TERM="xterm", COLUMNS="120").items() if k != "ONESTROKE_PROGRESS_SECONDS"}
    leader, follower = pty.openpty()
    process = subprocess.Popen([sys.executable, "-m", "fabrication.cli", "embroider", str(folder / "many.svg"),
                                "-o", str(tmp_path / "a.pes"), "--size", "180mm", "--hoop", "200x200"],
                               stdin=follower, stdout=follower, stderr=follower, env=env)
    os.close(follower)
    seen = b""
    try:
        while True:
            ready, _, _ = select.select([leader], [], [], 600)
            if not ready:
                break
            try:
                chunk = os.read(leader, 65536)
            except OSError:  # the other side closed
                break
            if not chunk:
                break
            seen += chunk
    finally:
        os.close(leader)
        process.wait(timeout=60)
    text = seen.decode("utf-8", "replace")
    assert process.returncode == 0, text
    import re

    assert "\x1b[" in text and "planning the stitches" in text, text
    assert re.search(r"stitching .*\d+%", text), text  # rich's bar with its percentage
    assert f"wrote {tmp_path / 'a.pes'}" in text


def test_laser_blur_exists_and_threshold_hint_does_not_chase_itself(folder, tmp_path):
    """`laser` on noise suggests --blur: laser has it. A threshold the user gave is not
    suggested again, lower (0.40 -> 0.35 -> 0.30 ...)."""
    result = CliRunner().invoke(main, ["laser", str(folder / "noise.png"), "-o", str(tmp_path / "a.gcode"),
                                       "--threshold", "0.35"])
    assert result.exit_code == 2 and "--blur" in result.stderr and "--threshold" not in result.stderr
    assert "--blur" in CliRunner().invoke(main, ["laser", "--help"]).output


def test_disk_full_is_one_line_and_leaves_nothing(folder, tmp_path, monkeypatch):
    """ENOSPC as the kernel reports it when the data reaches the disk (fsync)."""
    import errno

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    result = CliRunner().invoke(main, ["vectorize", str(folder / "d.svg"), "-o", str(tmp_path / "a.svg")])
    assert result.exit_code == 1 and result.stderr.strip() == \
        f"error: cannot write {str(tmp_path / 'a.svg')!r}: the disk is full"
    assert list(tmp_path.iterdir()) == []


def _child(*args, **kwargs):
    env = child_env()
    # "ready" once the interpreter itself is up: Ctrl-C before that is Python's, not ours.
    code = "import sys; print('ready', flush=True); from fabrication.cli import main; main()"
    return subprocess.Popen([sys.executable, "-c", code, *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True, **kwargs)


def test_file_size_limit_is_one_line_exit_1(folder, tmp_path):
    """A real EFBIG from the kernel (RLIMIT_FSIZE, SIGXFSZ ignored) while writing."""
    import resource

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (100, 100))

    child = _child("vectorize", str(folder / "d.svg"), "-o", str(tmp_path / "a.svg"), preexec_fn=limit)
    out, err = child.communicate(timeout=120)
    assert child.returncode == 1 and err.startswith("error: cannot write") and "Traceback" not in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("delay", [0.05, 0.15, 0.5])
def test_ctrl_c_while_importing_is_one_line(folder, tmp_path, delay):
    """Ctrl-C at once (click, rich being imported), a little later (numpy, scipy, the
    vectorizer) and during the work: "interrupted", exit 130, no traceback, no file."""
    def take_sigint():  # background test runs start children with SIGINT ignored
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    child = _child("vectorize", str(folder / "noise.png"), "-o", str(tmp_path / "a.svg"), preexec_fn=take_sigint)
    assert child.stdout.readline().strip() == "ready"
    time.sleep(delay)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=120)
    assert "Traceback" not in err, err
    assert (child.returncode, err.strip()) == (130, "interrupted"), (child.returncode, err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_169_megapixel_scan_is_read_downscaled_in_bands(tmp_path):
    """A 13,000 px square 1-bit scan (169 Mpx, past Pillow's bomb guard) just works,
    downscaled, and the whole command's peak memory (its VmHWM, in a child process) stays
    far under the 845 MB that decoding it and converting it to RGB needed."""
    from benchmarks.large_scans import run_vectorize

    image = Image.new("1", (13000, 13000), 1)
    ImageDraw.Draw(image).ellipse([2000, 2000, 11000, 11000], outline=0, width=60)
    image.save(tmp_path / "scan.png", compress_level=1)
    del image
    code, peak_mb, _, message = run_vectorize(tmp_path / "scan.png", tmp_path / "scan.svg")
    assert code == 0 and "downscaled" in message and (tmp_path / "scan.svg").stat().st_size > 0
    assert peak_mb < 300, peak_mb


def test_readme_zigzag_example_runs(tmp_path):
    """The README's zigzag example, as written, on the shipped example drawing."""
    import re
    import shlex
    from pathlib import Path

    readme = (Path(__file__).parents[2] / "README.md").read_text(encoding="utf-8")
    line = next(l for l in readme.splitlines() if l.startswith("onestroke embroider") and "--style zigzag" in l)
    args = shlex.split(line.split("#")[0])[1:]
    args[1] = str(Path(__file__).parents[2] / "examples" / "loops.png")
    args = [str(tmp_path / a) if re.fullmatch(r"[\w.-]+\.(jef|pes|png)", a) else a for a in args]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output


def test_readme_lists_every_command():
    """Item 7: every command of the group (emulator included) is shown in the README."""
    readme = (Path(__file__).parents[2] / "README.md").read_text(encoding="utf-8")
    missing = [name for name in main.list_commands(None) if f"onestroke {name}" not in readme]
    assert missing == []


def test_readme_states_the_laser_default_size_and_it_holds(tmp_path):
    """Item 7: without --size a raster is read at 96 px per inch (README); 800 px of ink
    burn 800 / 96 * 25.4 = 211.7 mm wide."""
    import re

    readme = (Path(__file__).parents[2] / "README.md").read_text(encoding="utf-8")
    assert "Without `--size`, `--width` or `--height` the design keeps the drawing's own size read at\n96 px per inch" \
        in readme
    image = np.full((300, 1000), 255, np.uint8)
    image[145:155, 100:900] = 0
    Image.fromarray(image).save(tmp_path / "bar.png")
    result = CliRunner().invoke(main, ["laser", str(tmp_path / "bar.png"), "-o", str(tmp_path / "bar.gcode")])
    assert result.exit_code == 0, result.output
    xs = [float(x) for x in re.findall(r"X(-?[\d.]+)", (tmp_path / "bar.gcode").read_text())]
    assert max(xs) - min(xs) == pytest.approx(800 / 96 * 25.4, abs=2.0)


def test_drawing_with_far_stroke_is_refused_in_the_library():
    with pytest.raises(ValueError, match="beyond the limit"):
        Drawing((Stroke.from_polyline(np.array([[0.0, 0.0], [2e7, 0.0]])),), 10, 10, "px")
    write_drawing  # noqa: B018 - imported for the fixture JSON's format name
