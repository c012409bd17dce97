#!/usr/bin/env python
"""The vectorizing that separates `onestroke vectorize` from its import floor: in-process CPU
of a process's first `vectorize_file` call and of warm calls, side by side for source trees.

    python -m benchmarks.first_call                          # this tree, the 15 drawings of --pairs 15
    python -m benchmarks.first_call /work/wt/base . --rounds 2   # two trees, alternating

For each drawing (the ones `startup_cost.py --pairs N` picks, rendered to PNG) and each tree,
a fresh process (PYTHONPATH=TREE, OPENBLAS_NUM_THREADS=1 as the command sets it, compiled
modules kept in a folder per tree) first imports exactly the third-party modules the command
loads on that drawing (`startup_ratio.py`'s listing), which the bare import floor imports too;
then it times (CPU: `time.process_time`) the project's own imports, the CNN's session, one
first `vectorize_file` call (after the command's heap and garbage collector settings,
`fabrication/cli/heap.py`, where the tree has them) and three warm calls (their median),
with each call's stage CPU. The trees alternate per drawing and per round. The project's
modules are imported before the collector's setting here, as the command imports them for
a raster drawing. Printed per tree: the median over drawings of each
drawing's fastest run (the least disturbed by other work on a shared machine), the median
over all runs, and the stages' medians. Compare trees only within one run (same load).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import hashlib, importlib, json, sys, time
listing, src = sys.argv[1], sys.argv[2]
for name in json.load(open(listing)):
    try:
        importlib.import_module(name)
    except Exception:
        pass
clock = time.process_time
out = {}
start = clock()
importlib.import_module("fabrication.cli.vectorize_cmd")
from vectorize import VectorizeOptions, vectorize_file
from vectorize.junctions.classifiers import make_classifier
from vectorize.svg_write import drawing_to_svg
importlib.import_module("vectorize.vectorizer")
out["project"] = clock() - start
options = VectorizeOptions()
start = clock()
make_classifier(options.classifier).session
out["session"] = clock() - start
try:  # the command's heap setting, where the tree has it
    from fabrication.cli.heap import keep_freed_memory
    keep_freed_memory()
except ImportError:
    pass
try:  # and its garbage collector's
    from fabrication.cli.heap import freeze_loaded_objects
    freeze_loaded_objects()
except ImportError:
    pass
start = clock()
result = vectorize_file(src, options)
out["first"] = clock() - start
out["first stages"] = result.report.cpu_seconds
out["svg"] = hashlib.sha256(drawing_to_svg(result.drawing).encode()).hexdigest()
warm = []
for _ in range(3):
    start = clock()
    result = vectorize_file(src, options)
    warm.append((clock() - start, result.report.cpu_seconds))
out["warm"], out["warm stages"] = sorted(warm, key=lambda item: item[0])[1]
print(json.dumps(out))
"""


def _env(tree: Path, cache: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree), "OPENBLAS_NUM_THREADS": "1",
           "PYTHONPYCACHEPREFIX": str(cache / str(tree).strip("/").replace("/", "_"))}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("trees", nargs="*", type=Path, default=[ROOT], help="source trees (default: this one)")
    ap.add_argument("--count", type=int, default=15, help="drawings, as startup_cost.py --pairs N picks them")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)

    from PIL import Image

    from benchmarks.common.render import render, to_uint8
    from benchmarks.common.startup_ratio import LIST_CHILD, PROJECT, third_party_roots
    from benchmarks.sets.registry import DEFAULT_COUNTS, SETS, build_set

    trees = [tree.resolve() for tree in args.trees]
    tasks = [gt for name in SETS for gt in build_set(name, DEFAULT_COUNTS[name], args.seed)]
    picks = tasks[:: max(1, len(tasks) // args.count)][: args.count]
    lister = LIST_CHILD.format(roots=repr(third_party_roots()), project=repr(PROJECT))
    runs: dict[Path, list[dict]] = {tree: [] for tree in trees}
    with tempfile.TemporaryDirectory(prefix="onestroke-first-") as tmp:
        folder = Path(tmp)
        drawings = []
        for k, gt in enumerate(picks):
            src, listing = folder / f"{k}.png", folder / f"{k}.json"
            Image.fromarray(to_uint8(render(gt.drawing))).save(src)
            subprocess.run([sys.executable, "-P", "-c", lister, str(listing), "vectorize", str(src), "-o",
                            str(folder / "out.svg")], env=_env(trees[0], folder), cwd=tmp, check=True,
                           capture_output=True, text=True)
            drawings.append((gt.name, src, listing))
        for tree in trees:  # compile each tree's modules once, unmeasured
            subprocess.run([sys.executable, "-P", "-c", CHILD, str(drawings[0][2]), str(drawings[0][1])],
                           env=_env(tree, folder), cwd=tmp, check=True, capture_output=True, text=True)
        print(f"{len(drawings)} drawings, {len(trees)} trees, {args.rounds} rounds; load average at the start "
              f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}  {time.strftime('%H:%M:%S %Z')}", flush=True)
        for r in range(args.rounds):
            for k, (name, src, listing) in enumerate(drawings):
                for tree in trees if (k + r) % 2 == 0 else trees[::-1]:
                    done = subprocess.run([sys.executable, "-P", "-c", CHILD, str(listing), str(src)],
                                          env=_env(tree, folder), cwd=tmp, capture_output=True, text=True)
                    if done.returncode != 0:
                        raise RuntimeError(f"{tree} on {name}: {done.stderr.strip()[-500:]}")
                    runs[tree].append({"name": name, **json.loads(done.stdout.strip().splitlines()[-1])})
    print(f"load average at the end {' '.join(f'{x:.1f}' for x in os.getloadavg())}  {time.strftime('%H:%M:%S %Z')}")
    for tree, rows in runs.items():
        fastest = {}
        for row in rows:
            best = fastest.setdefault(row["name"], [row["first"], row["warm"]])
            best[0], best[1] = min(best[0], row["first"]), min(best[1], row["warm"])
        print(f"{tree}\n  CPU s, median of each drawing's fastest: first call {statistics.median(b[0] for b in fastest.values()):.3f}, "
              f"warm {statistics.median(b[1] for b in fastest.values()):.3f}; median of all runs: first "
              f"{statistics.median(r['first'] for r in rows):.3f}, warm {statistics.median(r['warm'] for r in rows):.3f}; "
              f"project imports {statistics.median(r['project'] for r in rows):.3f}, session "
              f"{statistics.median(r['session'] for r in rows):.3f}")
        for stage in rows[0]["first stages"]:
            first = statistics.median(r["first stages"].get(stage, 0.0) for r in rows)
            warm = statistics.median(r["warm stages"].get(stage, 0.0) for r in rows)
            print(f"    {stage:16s} first {first * 1000:6.1f} ms   warm {warm * 1000:6.1f} ms")
    if len(trees) > 1:
        same = all(a["svg"] == b["svg"] for a, b in zip(runs[trees[0]], runs[trees[1]]))
        print(f"same SVG from the first two trees on every drawing: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
