"""Batch throughput: drawings per second on 1 and 2 worker processes and on a Dask
LocalCluster, and the start-up time a batch saves against one process per drawing.

Run from the repository root: python -m benchmarks.batch [--count 19] [--runs 3]
Every figure is the wall time of a whole `onestroke` command (a fresh process, as a user
runs it) on the drawings of benchmarks/sets/batch_drawings.py (360 px), median over --runs, each
run into an empty output folder. The cluster (2 worker processes, 1 thread each) is started
once beforehand, as an existing cluster would be.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.sets.batch_drawings import make_drawing_folder

ROOT = Path(__file__).resolve().parents[1]

TARGETS = "svg,pes,gcode"


def _run(args: list[str]) -> float:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "fabrication.cli", *args], capture_output=True, env=env,
                          cwd=ROOT, text=True)
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"onestroke {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()[-500:]}")
    return seconds


def _batch(folder: Path, work: Path, runs: int, to: str, extra: list[str]) -> float:
    times = []
    for run in range(runs):
        out = work / f"out-{time.monotonic_ns()}-{run}"
        times.append(_run(["batch", str(folder), "-o", str(out), "--to", to, *extra]))
    return statistics.median(times)


def _one_process_each(drawings: list[Path], work: Path, runs: int) -> float:
    times = []
    for _ in range(runs):
        total = 0.0
        for drawing in drawings:
            total += _run(["embroider", str(drawing), "-o", str(work / f"{drawing.stem}.pes")])
        times.append(total)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=19, help="drawings (at most 19 distinct ones)")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    from distributed import LocalCluster

    with tempfile.TemporaryDirectory(prefix="onestroke-batch-bench-") as tmp:
        work = Path(tmp)
        drawings = make_drawing_folder(work / "in", corrupt=False, count=args.count)
        n = len(drawings)
        print(f"{n} drawings of 360 px -> {TARGETS}; load before: {os.getloadavg()[0]:.2f} "
              f"on {os.cpu_count()} cores; median of {args.runs} runs")
        rates = {}
        for label, extra in (("1 worker", ["--jobs", "1"]), ("2 workers", ["--jobs", "2"])):
            rates[label] = n / _batch(work / "in", work, args.runs, TARGETS, extra)
            print(f"  {label:<28} {rates[label]:6.2f} drawings/s")
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            seconds = _batch(work / "in", work, args.runs, TARGETS, ["--scheduler", cluster.scheduler_address])
        print(f"  {'Dask LocalCluster, 2 workers':<28} {n / seconds:6.2f} drawings/s")

        # start-up: the same work (.pes only, one core) as one process per drawing vs one batch
        single = _one_process_each(drawings, work, args.runs)
        batch = _batch(work / "in", work, args.runs, "pes", ["--jobs", "1"])
        saved = 1.0 - batch / single
        print(f"one process per drawing (onestroke embroider): {single:.1f} s = {single / n:.2f} s per drawing")
        print(f"one batch process (--to pes --jobs 1):          {batch:.1f} s = {batch / n:.2f} s per drawing")
        print(f"start-up saved by the batch: {single - batch:.1f} s, {saved * 100:.0f} % of the per-process time "
              f"({(single - batch) / max(n - 1, 1):.2f} s per extra drawing); load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
