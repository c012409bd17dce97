#!/usr/bin/env python
"""What a whole `onestroke vectorize IN.png -o OUT.svg` process spends, part by part, and
how it compares with a bare process that imports the same libraries.

    python -m benchmarks.startup_cost              # the 9 drawings of `vectorize_bench.py --whole-process 9`
    python -m benchmarks.startup_cost --count 5 --repeat 3
    python -m benchmarks.startup_cost --pairs 15   # the command against the bare import floor, side by side

`--pairs N` (`benchmarks/common/startup_ratio.py`): N drawings (as `--whole-process N` picks them), each run
as the command and as a bare process importing exactly the third-party modules that
command loaded (found by an unmeasured run of the command in a process that lists them),
one right after the other (which one first alternates); the ratio command / bare per pair,
and its median (wall and CPU).

For each drawing (rendered to a PNG, as `vectorize_bench.py --whole-process` does) this
runs two kinds of fresh process, alternately:

- the command itself, `onestroke vectorize IN.png -o OUT.svg`: its wall time, and its CPU
  time (user + sys of the child, all its threads);
- a process that does what the command does, step by step, and times each part with
  `time.perf_counter` (wall) and `time.process_time` (CPU): the interpreter's own start
  (CPU used before the first line runs; its wall share is the process's wall time less
  the parts), the CLI's imports (click, the command's module), the vectorizer's imports
  library by library (`LIBRARIES`: each line adds only what the lines above did not
  already import), the CNN's onnxruntime session (import and session), reading the PNG, vectorizing it (the first call in the process), writing the
  SVG; and then, for comparison, vectorizing the same image again (warm, as the in-process
  benchmark measures it).

The figures are medians over the runs. On a machine shared with other work the wall time
includes waiting for a core; compare CPU time between versions (the load is printed).

What is measured is what a user runs: this working tree installed the regular way (`pip
install .`, modules compiled by pip) into a new virtual environment in a temporary folder,
its dependencies from this interpreter's (`benchmarks/common/user_install.py`). `--editable` measures the
working tree through PYTHONPATH instead, as the tests run it: with PYTHONDONTWRITEBYTECODE=1
in the environment every process then compiles the project's own modules from source; the
line "bytecode" says which was measured, and --pycache DIR lets the children keep compiled
modules in DIR.
"""

from __future__ import annotations

import json
import sys
import time

CHILD_FLAG = "--parts-child"
# What the vectorizer's imports bring in, in an order where each line adds only its own
# share (a module imported by an earlier line costs nothing again); the project's own
# modules come last.
LIBRARIES = (
    ("numpy", ("numpy",)),
    ("Pillow", ("PIL.Image", "PIL.PngImagePlugin")),
    ("scipy.ndimage", ("scipy.ndimage",)),
    ("scipy.sparse.csgraph", ("scipy.sparse.csgraph",)),
    ("scipy.spatial", ("scipy.spatial",)),
    ("scikit-image", ("skimage.filters.thresholding", "skimage.measure._find_contours")),
    ("shapely", ("shapely",)),
    ("scipy.optimize", ("scipy.optimize",)),
    ("scipy.interpolate", ("scipy.interpolate",)),
)


def _parts_child(source: str, output: str) -> None:
    """The command's work in the command's order, each part timed; prints one JSON line."""
    marks = [("interpreter", time.perf_counter(), time.process_time())]

    def mark(name: str) -> None:
        marks.append((name, time.perf_counter(), time.process_time()))

    import importlib

    importlib.import_module("fabrication.cli")
    importlib.import_module("fabrication.cli.vectorize_cmd")
    mark("CLI imports")
    for name, modules in LIBRARIES:
        for module in modules:
            importlib.import_module(module)
        mark(f"  {name}")
    from vectorize import VectorizeOptions, vectorize_image
    from vectorize.raster.image_io import load_image
    from vectorize.svg_write import write_drawing

    importlib.import_module("vectorize.vectorizer")
    mark("  the project's modules")
    from vectorize.junctions.classifiers import make_classifier

    options = VectorizeOptions()
    make_classifier(options.classifier).session  # noqa: B018 - onnxruntime import and session
    mark("model session")
    from fabrication.cli.heap import freeze_loaded_objects, keep_freed_memory

    keep_freed_memory()  # the command's heap and garbage collector settings
    freeze_loaded_objects()
    image, frame = load_image(source, max_size=options.max_size)
    mark("read PNG")
    result = vectorize_image(image, options, frame=frame)
    mark("vectorize")
    write_drawing(result.drawing, output)
    mark("write SVG")
    vectorize_image(image, options, frame=frame)
    mark("vectorize again (warm)")
    parts = {"interpreter": {"wall": None, "cpu": marks[0][2]}}
    for (_, w0, c0), (name, w1, c1) in zip(marks, marks[1:]):
        parts[name] = {"wall": w1 - w0, "cpu": c1 - c0}
    print(json.dumps(parts))


def _timed(cmd: list[str], env: dict, timeout: float) -> tuple[float, float, str]:
    """(wall s, CPU s of the child, stdout) of one process run to the end."""
    import subprocess

    from benchmarks.common.processes import child_cpu_seconds

    cpu0, start = child_cpu_seconds(), time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    wall, cpu = time.perf_counter() - start, child_cpu_seconds() - cpu0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:3])} ... exited {proc.returncode}: {proc.stderr.strip()[-300:]}")
    return wall, cpu, proc.stdout


def main(argv: list[str] | None = None) -> int:
    import argparse
    import os
    import shutil
    import tempfile
    from pathlib import Path

    from benchmarks.common.user_install import bytecode_note
    from benchmarks.sets.registry import DEFAULT_COUNTS, SETS, build_set

    root = Path(__file__).resolve().parents[1]

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("--count", type=int, default=9, help="drawings, picked across all sets as --whole-process picks")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each kind per drawing")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--pairs", type=int, default=None, metavar="N",
                    help="instead: N pairs of the command and a bare process importing the same libraries")
    ap.add_argument("--editable", action="store_true",
                    help="measure the working tree through PYTHONPATH (as the tests run it) instead of a regular "
                         "install of it")
    ap.add_argument("--pycache", type=Path, default=None, metavar="DIR",
                    help="with --editable: let the children write and read compiled modules in DIR "
                         "(PYTHONPYCACHEPREFIX); one unmeasured run first fills it")
    args = ap.parse_args(argv)

    tasks = [gt for name in SETS for gt in build_set(name, DEFAULT_COUNTS[name], args.seed)]
    count = args.pairs or args.count
    picks = tasks[:: max(1, len(tasks) // count)][:count]
    with tempfile.TemporaryDirectory(prefix="onestroke-startup-") as tmp:
        if args.editable:
            env = {**os.environ,
                   "PYTHONPATH": os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
            if args.pycache is not None:
                env.pop("PYTHONDONTWRITEBYTECODE", None)
                env["PYTHONPYCACHEPREFIX"] = str(args.pycache.resolve())
            python, exe = sys.executable, shutil.which("onestroke")
            command = [exe] if exe else [sys.executable, "-m", "fabrication.cli"]
        else:
            from benchmarks.common.user_install import regular_install

            env = dict(os.environ)
            bin_dir = regular_install(Path(tmp) / "venv", root)
            python, command = str(bin_dir / "python"), [str(bin_dir / "onestroke")]
        note = bytecode_note(env, installed=not args.editable)
        if args.pairs:
            from benchmarks.common.startup_ratio import ratio_pairs

            print(f"bytecode: {note}")
            return ratio_pairs(picks, command, python, env, args.timeout)
        return _parts(picks, command, python, env, note, args.repeat, args.timeout, Path(tmp),
                      fill_cache=args.pycache is not None and args.editable)


def _parts(picks: list, command: list[str], python: str, env: dict, note: str, repeat: int, timeout: float,
           tmp: Path, fill_cache: bool) -> int:
    """Run the command and the step-by-step process on each drawing; print the parts' medians."""
    import os
    import statistics

    from PIL import Image

    from benchmarks.common.render import render, to_uint8

    whole_wall, whole_cpu, parts = [], [], {}
    for gt in picks:
        src, out = tmp / f"{gt.name}.png", tmp / f"{gt.name}.svg"
        Image.fromarray(to_uint8(render(gt.drawing))).save(src)
    if fill_cache:  # fill the cache: not measured
        _timed(command + ["vectorize", str(src), "-o", str(out)], env, timeout)
    for _ in range(repeat):
        for gt in picks:
            src, out = tmp / f"{gt.name}.png", tmp / f"{gt.name}.svg"
            wall, cpu, _ = _timed(command + ["vectorize", str(src), "-o", str(out)], env, timeout)
            whole_wall.append(wall)
            whole_cpu.append(cpu)
            wall, cpu, stdout = _timed([python, __file__, CHILD_FLAG, str(src), str(out)], env, timeout)
            measured = json.loads(stdout.strip().splitlines()[-1])
            inside = sum(p["wall"] for name, p in measured.items() if p["wall"] is not None)
            measured["interpreter"]["wall"] = wall - inside
            for name, p in measured.items():
                parts.setdefault(name, {"wall": [], "cpu": []})
                parts[name]["wall"].append(p["wall"])
                parts[name]["cpu"].append(p["cpu"])
            warm = measured["vectorize again (warm)"]  # not part of what the command does
            parts.setdefault("(process total)", {"wall": [], "cpu": []})
            parts["(process total)"]["wall"].append(wall - warm["wall"])
            parts["(process total)"]["cpu"].append(cpu - warm["cpu"])

    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"start-up cost of `onestroke vectorize IN.png -o OUT.svg`: {len(picks)} drawings x {repeat} runs, "
          f"{os.cpu_count()} CPUs, load average {load}")
    print(f"bytecode: {note}")
    print(f"the command:   wall median {statistics.median(whole_wall):.3f} s, max {max(whole_wall):.3f} s;  "
          f"CPU (user+sys) median {statistics.median(whole_cpu):.3f} s")
    print("its parts (a process doing the same steps), medians:")
    print(f"  {'part':26s} {'wall s':>8s} {'CPU s':>8s}")
    for name, values in parts.items():
        if name == "(process total)" or name.startswith("vectorize again"):
            continue
        if name == "  numpy":
            print("  vectorizer imports:")
        print(f"  {name:26s} {statistics.median(values['wall']):8.3f} {statistics.median(values['cpu']):8.3f}")
    total = parts["(process total)"]
    print(f"  {'(process total)':26s} {statistics.median(total['wall']):8.3f} {statistics.median(total['cpu']):8.3f}")
    warm = parts["vectorize again (warm)"]
    print(f"  {'vectorize again (warm)':26s} {statistics.median(warm['wall']):8.3f} {statistics.median(warm['cpu']):8.3f}"
          "   (not in the total: the in-process figure, for comparison)")
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == CHILD_FLAG:
        # The project as installed in the measured environment: the path stays as it is.
        _parts_child(sys.argv[2], sys.argv[3])
    else:
        import os

        if os.path.realpath(sys.path[0]) == os.path.dirname(os.path.realpath(__file__)):
            sys.path[0] = os.path.dirname(sys.path[0])  # run as a file: see benchmarks/__init__.py
        sys.exit(main())
