"""The hostile-input cases of issue 28 (items 1-5), each run as a user would: a fresh
`onestroke` process, its exit code, first message line, wall time and peak memory.

    python -m benchmarks.hostile_cases                  # every case, 60 s and 3 GB bound each
    python -m benchmarks.hostile_cases --only svg- --time-bound 20
    PYTHONPATH=/path/to/other/checkout python -m benchmarks.hostile_cases   # the same cases on other code

A case still running at the time bound, or over the memory bound, is killed (its whole
process group) and reported as such. Prints one row per case (markdown table).
"""

from __future__ import annotations

import argparse
import gzip
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

PATH = ('<path d="M 10 10 L 90 90" stroke="black" fill="none"/>')
SVG_HEAD = '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="100" height="100">'
WAVE = (SVG_HEAD + '<path d="M 10 50 C 30 10, 50 90, 90 50" stroke="black" fill="none"/></svg>')


def _nested_use(levels: int) -> str:
    """`levels` <g>, each using the one before twice: 2**levels paths once expanded."""
    defs = ['<path id="u0" d="M 10 10 L 90 90" stroke="black" fill="none"/>']
    for level in range(1, levels + 1):
        defs.append(f'<g id="u{level}"><use href="#u{level - 1}"/><use href="#u{level - 1}"/></g>')
    return SVG_HEAD + "<defs>" + "".join(defs) + f'</defs><use href="#u{levels}"/></svg>'


def _comment(megabytes: int) -> str:
    return SVG_HEAD + "<!--" + "a" * (megabytes * 1_000_000) + "-->" + PATH + "</svg>"


def _gcode(*middle: str) -> str:
    """A small job with `middle` after a dwell (G4 P0: the machine is Idle there, where GRBL
    takes any `$` command), then more moves."""
    return "\n".join(["G21", "G90", "M4 S0", "G0 X1 Y1", "G1 X5 Y5 F600 S300", "G4 P0", *middle, "G1 X9 Y2", "M5",
                      ""])


def _png(folder: Path, name: str, width: int, height: int) -> None:
    from PIL import Image

    Image.new("L", (width, height), 255).save(folder / name)


def _files(folder: Path) -> None:
    """Every input the cases read, written into `folder`."""
    text = {
        "use21.svg": _nested_use(21),
        "comment16.svg": _comment(16),
        "comment60.svg": _comment(60),
        "arc.svg": SVG_HEAD + '<path d="M 0 0 A 1e308 1e308 0 1 1 10 10" stroke="black" fill="none"/></svg>',
        "transform.svg": SVG_HEAD + '<g transform="scale(1e308) rotate(45)">' + PATH + "</g></svg>",
        "wave.svg": WAVE,
        "list.json": "[1,2,3]",
        "types.json": '{"format": "onestroke-drawing", "width": "wide", "height": 10, "strokes": {"a": 1}}',
        "edits-list.json": "[1,2,3]",
        "edits-types.json": '{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "split", "at": "here"}]}',
    }
    for name, body in text.items():
        (folder / name).write_text(body, encoding="utf-8")
    (folder / "random.json").write_bytes(os.urandom(4096) + b"\xff\xfe")
    (folder / "wave.svgz").write_bytes(gzip.compress(WAVE.encode()))
    _png(folder, "tall.png", 1, 5000)
    _png(folder, "drawing.png", 64, 64)
    os.mkfifo(folder / "fifo.svg")
    os.symlink("/dev/zero", folder / "zero.svg")
    for name, extra in {"home.gcode": ("$H",), "jog-nof.gcode": ("$J=G91 X1",), "jog-g1.gcode": ("$J=G1 X1 F100",),
                        "set999.gcode": ("$999=1",), "q.gcode": ("$Q",), "check.gcode": ("$C",),
                        "sleep.gcode": ("$SLP",), "rst.gcode": ("$RST=*",)}.items():
        (folder / name).write_text(_gcode(*extra), encoding="ascii")
    # a long zigzag sewn slowly: sewing minutes next to the command's own seconds
    points = " ".join(f"L {x} {10 + 80 * (x % 2)}" for x in range(11, 90))
    (folder / "dense.svg").write_text(SVG_HEAD + f'<path d="M 10 10 {points}" stroke="black" fill="none"/></svg>')


# (name, issue item, command line after `onestroke`)
CASES = [
    ("svg-use21-vectorize", 1, ["vectorize", "use21.svg", "-o", "o.svg"]),
    ("svg-use21-embroider", 1, ["embroider", "use21.svg", "-o", "o.pes"]),
    ("svg-use21-laser", 1, ["laser", "use21.svg", "-o", "o.gcode"]),
    ("svg-use21-preview", 1, ["preview", "use21.svg", "-o", "o.png"]),
    ("svg-comment16", 1, ["vectorize", "comment16.svg", "-o", "o.svg"]),
    ("svg-comment60", 1, ["vectorize", "comment60.svg", "-o", "o.svg"]),
    ("svg-arc1e308-vectorize", 1, ["vectorize", "arc.svg", "-o", "o.svg"]),
    ("svg-arc1e308-embroider", 1, ["embroider", "arc.svg", "-o", "o.pes"]),
    ("svg-arc1e308-laser", 1, ["laser", "arc.svg", "-o", "o.gcode"]),
    ("svg-arc1e308-preview", 1, ["preview", "arc.svg", "-o", "o.png"]),
    ("svg-scale1e308", 1, ["vectorize", "transform.svg", "-o", "o.svg"]),
    ("json-list-preview", 2, ["preview", "list.json", "-o", "o.png"]),
    ("json-list-embroider", 2, ["embroider", "list.json", "-o", "o.pes"]),
    ("json-random-preview", 2, ["preview", "random.json", "-o", "o.png"]),
    ("json-random-embroider", 2, ["embroider", "random.json", "-o", "o.pes"]),
    ("json-types-preview", 2, ["preview", "types.json", "-o", "o.png"]),
    ("json-types-player", 2, ["preview", "types.json", "-o", "o.html"]),
    ("edits-list", 2, ["vectorize", "drawing.png", "-o", "o.svg", "--edits", "edits-list.json"]),
    ("edits-types", 2, ["vectorize", "drawing.png", "-o", "o.svg", "--edits", "edits-types.json"]),
    ("sim-speed-nan", 3, ["laser", "wave.svg", "-o", "o.gcode", "--port", "sim://?speed=nan"]),
    ("sim-rx-0", 3, ["laser", "wave.svg", "-o", "o.gcode", "--port", "sim://?rx=0"]),
    ("ports-baud-0", 3, ["ports", "--no-probe", "--baud", "0"]),
    ("ports-baud--1", 3, ["ports", "--no-probe", "--baud", "-1"]),
    ("ports-baud-1e20", 3, ["ports", "--no-probe", "--baud", "1e20"]),
    ("passes-1_0", 3, ["laser", "wave.svg", "-o", "o.gcode", "--passes", "1_0"]),
    ("rotate-1_0", 3, ["laser", "wave.svg", "-o", "o.gcode", "--rotate", "1_0"]),
    ("passes-arabic", 3, ["laser", "wave.svg", "-o", "o.gcode", "--passes", "\u0663"]),
    ("rotate-fullwidth", 3, ["laser", "wave.svg", "-o", "o.gcode", "--rotate", "\uff11\uff10"]),
    ("size-fullwidth", 3, ["laser", "wave.svg", "-o", "o.gcode", "--size", "\uff19\uff10mm"]),
    ("size-1_0mm", 3, ["laser", "wave.svg", "-o", "o.gcode", "--size", "1_0mm"]),
    ("settings-$H", 4, ["stream", "home.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$J-noF", 4, ["stream", "jog-nof.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$J-G1", 4, ["stream", "jog-g1.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$999", 4, ["stream", "set999.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$Q", 4, ["stream", "q.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$C", 4, ["stream", "check.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$SLP", 4, ["stream", "sleep.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("settings-$RST", 4, ["stream", "rst.gcode", "--port", "sim://?speed=100", "--allow-settings"]),
    ("fifo", 5, ["vectorize", "fifo.svg", "-o", "o.svg"]),
    ("symlink-dev-zero", 5, ["vectorize", "zero.svg", "-o", "o.svg"]),
    ("image-1x5000", 5, ["vectorize", "tall.png", "-o", "o.svg"]),
    ("stream-svg", 5, ["stream", "wave.svg", "--port", "sim://"]),
    ("svgz-vectorize", 5, ["vectorize", "wave.svgz", "-o", "o.svg"]),
    ("svgz-batch", 5, ["batch", "wave.svgz", "-o", "batch-out", "--to", "svg"]),
    ("sewing-time", 5, ["embroider", "dense.svg", "-o", "o.pes", "--spm", "100"]),
]


def _rss_kb(pid: int) -> int:
    """Resident memory of `pid` and its children (kB), from /proc."""
    total = 0
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as handle:
                fields = handle.read().rsplit(")", 1)[1].split()
            if int(entry) == pid or int(fields[2]) == pid or int(fields[4]) == pid:  # self, child, same group
                with open(f"/proc/{entry}/status") as handle:
                    total += next(int(line.split()[1]) for line in handle if line.startswith("VmRSS:"))
        except (OSError, StopIteration, IndexError, ValueError):
            continue
    return total


def run(args: list[str], folder: Path, *, time_bound: float, memory_mb: float) -> dict:
    """One command line in `folder`; its exit code, message, seconds and peak MB."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [os.environ.get("PYTHONPATH"), str(ROOT)])))
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-m", "fabrication.cli", *args], cwd=folder, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                               start_new_session=True)
    peak, verdict = 0, None
    while process.poll() is None:
        peak = max(peak, _rss_kb(process.pid))
        elapsed = time.perf_counter() - started
        if elapsed > time_bound or peak > memory_mb * 1024:
            verdict = f"killed: still running at {elapsed:.0f} s" if elapsed > time_bound else \
                f"killed: over {memory_mb:g} MB"
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            break
        time.sleep(0.05)
    seconds = time.perf_counter() - started
    output = process.stdout.read().decode("utf-8", "replace").strip().splitlines()
    lines = [line for line in output if line.startswith("error:")] or output[-1:] or [""]
    return {"code": None if verdict else process.returncode, "seconds": seconds, "mb": peak / 1024,
            "message": verdict or lines[0]}


ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="", help="run the cases whose name starts with this")
    ap.add_argument("--time-bound", type=float, default=60.0, help="seconds per case")
    ap.add_argument("--memory-bound", type=float, default=3000.0, help="MB per case")
    args = ap.parse_args()
    print(f"code: {os.environ.get('PYTHONPATH') or ROOT}")
    print("| case | item | exit | seconds | peak MB | first message |\n|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _files(folder)
        for name, item, command in CASES:
            if not name.startswith(args.only):
                continue
            outcome = run(command, folder, time_bound=args.time_bound, memory_mb=args.memory_bound)
            message = outcome["message"].replace("|", "\\|")[:230]
            print(f"| {name} | {item} | {outcome['code']} | {outcome['seconds']:.1f} | {outcome['mb']:.0f} | "
                  f"{message} |", flush=True)
            for left in folder.glob("o.*"):
                left.unlink()


if __name__ == "__main__":
    main()
