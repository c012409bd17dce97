#!/usr/bin/env python
"""CPU seconds per pipeline stage on a sample of the benchmark sets (issue 10's speed work).

    python -m benchmarks.stage_cpu                  # every 8th drawing of each set (35)
    python -m benchmarks.stage_cpu --step 4 --cprofile 30

On a machine shared with other work the wall time includes waiting for a core; the CPU
time (`time.process_time`, all threads of this process) does not, so it is what to compare
before and after a change (run both versions side by side, at the same time, to give them
the same load). Each drawing is vectorized once after one warm-up call (modules and the
model loaded, as in a long-running process); the figures are medians over the drawings of
the report's `cpu_seconds` per stage and of the whole `vectorize_image` call.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.common.render import render
from benchmarks.vectorize_bench import SETS, build_set


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("--step", type=int, default=8, help="take every STEP-th of the 40 drawings of each set")
    ap.add_argument("--classifier", default="cnn", choices=["cnn", "geometric"])
    ap.add_argument("--cprofile", type=int, default=0, metavar="N",
                    help="also print the N functions with the most CPU time of their own (cProfile)")
    args = ap.parse_args(argv)

    from vectorize import VectorizeOptions, vectorize_image

    images = [(f"{name}-{gt.name}", render(gt.drawing)) for name in SETS for gt in build_set(name, 40, 0)[::args.step]]
    options = VectorizeOptions(multi=False, classifier=args.classifier, seed=0)
    vectorize_image(images[0][1], options)  # warm-up: imports, model session
    profile = cProfile.Profile(time.process_time) if args.cprofile else None
    totals, stages = [], {}
    for _name, image in images:
        start = time.process_time()
        if profile:
            profile.enable()
        report = vectorize_image(image, options).report
        if profile:
            profile.disable()
        totals.append(time.process_time() - start)
        for stage, seconds in report.cpu_seconds.items():
            stages.setdefault(stage, []).append(seconds)
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"{len(images)} drawings (every {args.step}th of each set), classifier {args.classifier}, load {load}")
    print(f"CPU s per drawing: median {statistics.median(totals):.3f}, mean {statistics.fmean(totals):.3f}, "
          f"max {max(totals):.3f}")
    for stage, values in stages.items():
        print(f"  {stage:16s} median {statistics.median(values):.4f}  mean {statistics.fmean(values):.4f}")
    if profile:
        pstats.Stats(profile).sort_stats("tottime").print_stats(args.cprofile)
    return 0


if __name__ == "__main__":
    sys.exit(main())
