"""Benchmark: the CLI on large SVG inputs (issue 14, "silence on long work").

Run from the repo root: `python -m benchmarks.large_inputs [--paths 20000] [--segments 10000]
[--only embroider,laser]`. Writes two seeded SVGs to a temporary folder:

- many.svg: `--paths` short cubic paths (3 segments each) scattered over 200 x 150 mm;
- long.svg: ONE path of `--segments` cubic segments (a smooth random walk);

then runs each command below in a fresh process and prints its CPU time (user + system of
the child, which a loaded machine disturbs less than wall time), its wall time and the
SHA-256 of what it wrote (to check that a speed-up keeps the bytes).
"""

from __future__ import annotations

import argparse
import hashlib
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "vectorize-many": ["vectorize", "many.svg", "-o", "many.out.svg"],
    "embroider-many": ["embroider", "many.svg", "-o", "many.pes", "--size", "180mm", "--hoop", "200x200"],
    "laser-many": ["laser", "many.svg", "-o", "many.gcode", "--size", "180mm"],
    "preview-many": ["preview", "many.svg", "-o", "many.png"],
    "preview-many-pes": ["preview", "many.pes", "-o", "many.pes.png"],
    "preview-many-gcode": ["preview", "many.gcode", "-o", "many.gcode.png"],
    "embroider-long": ["embroider", "long.svg", "-o", "long.pes", "--size", "180mm", "--hoop", "200x200"],
    "laser-long": ["laser", "long.svg", "-o", "long.gcode", "--size", "180mm"],
    "preview-long": ["preview", "long.svg", "-o", "long.png"],
}


def _number(value: float) -> str:
    return f"{value:.3f}".rstrip("0").rstrip(".")


def many_paths_svg(paths: int, seed: int = 0) -> str:
    """`paths` separate short cubic paths, each of 3 segments, on a 200 x 150 mm canvas."""
    rng = np.random.default_rng(seed)
    body = []
    for _ in range(paths):
        start = rng.uniform([5, 5], [195, 145])
        points = start + np.cumsum(rng.normal(0, 1.5, (9, 2)), axis=0)
        d = f"M {_number(start[0])} {_number(start[1])} " + " ".join(
            "C " + ", ".join(f"{_number(x)} {_number(y)}" for x, y in points[i:i + 3]) for i in range(0, 9, 3))
        body.append(f'<path d="{d}" fill="none" stroke="black" stroke-width="0.4"/>')
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="150mm" viewBox="0 0 200 150">\n'
            + "\n".join(body) + "\n</svg>\n")


def long_path_svg(segments: int, seed: int = 1) -> str:
    """ONE path of `segments` smooth cubic segments wandering over a 200 x 150 mm canvas."""
    rng = np.random.default_rng(seed)
    heading = np.cumsum(rng.normal(0, 0.5, segments))
    steps = np.c_[np.cos(heading), np.sin(heading)] * 1.2
    ends = np.empty((segments + 1, 2))
    ends[0] = (100, 75)
    for i, step in enumerate(steps):  # reflect at the canvas edges so the walk stays inside
        nxt = ends[i] + step
        for axis, high in ((0, 200), (1, 150)):
            if not 2 < nxt[axis] < high - 2:
                steps[i:, axis] *= -1
                nxt[axis] = ends[i][axis] - step[axis]
        ends[i + 1] = nxt
    tangent = np.gradient(ends, axis=0) / 3
    parts = [f"M {_number(ends[0][0])} {_number(ends[0][1])}"]
    for i in range(segments):
        c1, c2, end = ends[i] + tangent[i], ends[i + 1] - tangent[i + 1], ends[i + 1]
        parts.append("C " + ", ".join(f"{_number(x)} {_number(y)}" for x, y in (c1, c2, end)))
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="150mm" viewBox="0 0 200 150">\n'
            f'<path d="{" ".join(parts)}" fill="none" stroke="black" stroke-width="0.4"/>\n</svg>\n')


def run(name: str, args: list[str], folder: Path) -> tuple[float, float, int, str]:
    """(cpu seconds, wall seconds, exit code, sha256 prefix of the output) of one command."""
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "fabrication.cli", *args], cwd=folder, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode:
        print(f"  {name}: exit {done.returncode}: {done.stderr.strip()[-300:]}", file=sys.stderr)
    output = folder / args[args.index("-o") + 1]
    digest = hashlib.sha256(output.read_bytes()).hexdigest()[:16] if output.exists() else "-"
    return cpu, wall, done.returncode, digest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--paths", type=int, default=20_000, help="paths in many.svg")
    parser.add_argument("--segments", type=int, default=10_000, help="cubic segments of the path in long.svg")
    parser.add_argument("--only", default="", help="comma-separated names of the commands to run")
    parser.add_argument("--keep", default=None, help="write the inputs and outputs to this folder")
    options = parser.parse_args()
    chosen = [n for n in options.only.split(",") if n] or list(COMMANDS)
    unknown = set(chosen) - set(COMMANDS)
    if unknown:
        parser.error(f"unknown command(s) {sorted(unknown)}; choose from {', '.join(COMMANDS)}")

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(options.keep or scratch)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "many.svg").write_text(many_paths_svg(options.paths), encoding="utf-8")
        (folder / "long.svg").write_text(long_path_svg(options.segments), encoding="utf-8")
        print(f"many.svg: {options.paths} paths; long.svg: 1 path of {options.segments} segments; "
              f"load {os.getloadavg()[0]:.1f}")
        print(f"{'command':20s} {'cpu s':>8s} {'wall s':>8s} {'exit':>4s}  sha256")
        for name in chosen:
            args = COMMANDS[name]
            needs = args[1]
            if not (folder / needs).exists():
                print(f"{name:20s} skipped: {needs} was not made")
                continue
            cpu, wall, code, digest = run(name, args, folder)
            print(f"{name:20s} {cpu:8.2f} {wall:8.2f} {code:4d}  {digest}", flush=True)


if __name__ == "__main__":
    main()
