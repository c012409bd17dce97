"""Embroidery speed: stitches generated and written to .pes, medians over repeated runs.

Run from the repository root: python -m benchmarks.embroidery_speed [--runs 7]
The design is one long spiral (a single stroke, like the vectorizer's output) sized so
that each style makes about 100,000 needle points.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np


from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.plan import PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.preview import PreviewOptions, render_stitch_preview
from fabrication.embroidery.stats import embroidery_stats
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def spiral_drawing(turns: float, r0: float = 5.0, r1: float = 95.0, per_turn: int = 8) -> Drawing:
    """One spiral stroke of cubic segments (Hermite tangents), radius r0 -> r1 mm."""
    n = int(turns * per_turn)
    th = np.linspace(0.0, 2 * np.pi * turns, n + 1)
    r = r0 + (r1 - r0) * th / th[-1]
    p = np.c_[r * np.cos(th), r * np.sin(th)]
    dr = (r1 - r0) / th[-1]
    d = np.c_[dr * np.cos(th) - r * np.sin(th), dr * np.sin(th) + r * np.cos(th)]
    h = np.diff(th)[:, None] / 3.0
    control = np.stack([p[:-1], p[:-1] + d[:-1] * h, p[1:] - d[1:] * h, p[1:]], axis=1)
    return Drawing((Stroke(control),), 2 * r1, 2 * r1, "mm")


# Turns that give about 100,000 needle points per style (curve ~251 m for running).
CASES = {"running": 800.0, "triple": 267.0, "zigzag": 57.0, "satin": 57.0, "arrows": 285.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    print(f"{'style':8} {'curve m':>8} {'needles':>8} {'plan s':>7} {'pes s':>7} {'total s':>8} "
          f"{'cpu s':>6} {'best s':>7} {'stats s':>8} {'png s':>6}   (medians of {args.runs} runs; "
          "total = plan + .pes write, wall clock; cpu = the same in process CPU time; "
          "best = fastest total)")
    with tempfile.TemporaryDirectory() as folder:
        for style, turns in CASES.items():
            drawing = spiral_drawing(turns)
            options = PlanOptions(style=style_options(style))
            plan_times, write_times, totals, stats_times, cpus = [], [], [], [], []
            for _ in range(args.runs):
                c0 = time.process_time()
                t0 = time.perf_counter()
                plan = plan_embroidery(drawing, options)
                t1 = time.perf_counter()
                write_embroidery(plan, f"{folder}/bench.pes")
                t2 = time.perf_counter()
                cpus.append(time.process_time() - c0)
                embroidery_stats(plan)
                t3 = time.perf_counter()
                plan_times.append(t1 - t0)
                write_times.append(t2 - t1)
                totals.append(t2 - t0)
                stats_times.append(t3 - t2)
            t4 = time.perf_counter()
            render_stitch_preview(plan, f"{folder}/bench.png", options=PreviewOptions(width=1000))
            png = time.perf_counter() - t4
            needles = int((plan.kinds == 0).sum())
            print(f"{style:8} {drawing.length / 1000:8.1f} {needles:8d} {statistics.median(plan_times):7.3f} "
                  f"{statistics.median(write_times):7.3f} {statistics.median(totals):8.3f} "
                  f"{statistics.median(cpus):6.3f} {min(totals):7.3f} "
                  f"{statistics.median(stats_times):8.3f} {png:6.2f}")
    merge_scaling()


def merge_scaling() -> None:
    """Short-stitch merging on rows that nearly all merge (what a 0.0001 mm stitch length
    used to make): the time must grow in proportion to the rows, not their square."""
    from fabrication.embroidery.needles import BODY, LOCK
    from fabrication.embroidery.grid import merge_short as _merge_short
    from fabrication.embroidery.needles import STITCH

    print(f"\n{'rows':>9} {'merge s':>8} {'us/row':>7}   (every stitch 0.1 grid unit, minimum 3 units)")
    for n in (10_000, 100_000, 1_000_000):
        units = np.column_stack([np.arange(n) // 10, np.zeros(n, dtype=np.int64)])
        kinds = np.full(n, STITCH, dtype=np.uint8)
        roles = np.full(n, BODY, dtype=np.uint8)
        roles[-4:] = LOCK
        t0 = time.perf_counter()
        keep = _merge_short(units, kinds, roles, 3.0 - 1e-9)
        elapsed = time.perf_counter() - t0
        print(f"{n:9d} {elapsed:8.3f} {elapsed / n * 1e6:7.2f}   ({int(keep.sum())} rows kept)")


if __name__ == "__main__":
    main()
