"""Benchmark: the medial axis stage alone (`vectorize.axis.medial_axis.medial_axis`), whole and in
tiles.

Run from the repo root: `python -m benchmarks.medial_axis_speed [DRAWING ...] [--tsp N]
[--repeats R] [--source DIR]` (default: the 1000 px examples loops.png, touch-drawing.png and
the hershey ampersand; --tsp adds the first N TSP-art drawings of the `kinds` set, ~300,000
outline samples each). Each drawing is binarized and outlined as the vectorizer does, then
its medial axis is computed R (7) times per way, and the medians are printed:

- wall and CPU seconds (all threads) of the whole diagram (`tiles=1`) and in one tile per
  core (what the default does from `TILED_SAMPLES` outline samples on while the load
  average leaves a core to spare);
- "idle": the default's CPU minus its tiles' CPU plus the longest tile's (each worker's
  `time.thread_time`): its wall time on a machine with a free core per tile. On a loaded
  machine the wall columns include waiting for a core (the load average is printed).

--source DIR imports `vectorize` from DIR (another checkout, e.g. a worktree of an older
commit, whose `medial_axis` may have no `tiles`: then only the whole diagram is timed), in
a child interpreter (benchmarks/common/checkout.py).
"""

from __future__ import annotations

import argparse
import inspect
import os
import sys
import time
from pathlib import Path
from statistics import median

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.common.checkout import needs_rerun, rerun_on

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ["examples/loops.png", "examples/touch-drawing.png", "examples/hershey-HersheySans1-ampersand.png"]


def _inputs(image, vectorize_modules):
    """(rings, gray, level) as `vectorize.vectorizer` hands them to `medial_axis`."""
    import numpy as np

    binarize, outline_rings = vectorize_modules
    ink = binarize(image, max_size=1000, blur=0.0, threshold=None)
    spacing = float(np.clip(ink.stroke_width / 8.0, 0.3, 1.0))
    return outline_rings(ink.gray, ink.threshold, spacing), ink.gray, ink.threshold


def _tsp_images(count: int):
    """The first `count` TSP drawings of the kinds set, rendered as the benchmark does."""
    import numpy as np

    from benchmarks.sets.conditions import condition_image
    from benchmarks.common.render import render_truth
    from benchmarks.sets.tsp_art import tsp_drawing

    for index in range(count):
        gt = tsp_drawing(0, index)
        image, _ = condition_image(gt.drawing, render_truth(gt), gt.meta.get("condition", "clean"),
                                   np.random.default_rng(index))
        yield gt.name, image


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("drawings", nargs="*", type=Path)
    ap.add_argument("--tsp", type=int, default=0, help="add the first N TSP-art drawings of the kinds set")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--source", type=Path, default=ROOT, help="the checkout whose vectorize to time")
    args = ap.parse_args(argv)
    if needs_rerun(args.source):
        return rerun_on(args.source, __file__, sys.argv[1:] if argv is None else argv)
    from concurrent.futures import ThreadPoolExecutor

    import vectorize.axis.medial_axis as medial
    from vectorize.raster.binarize import binarize
    from vectorize.raster.image_io import load_image
    from vectorize.raster.outline import outline_rings

    tile_cpu: list[float] = []

    class TimedPool(ThreadPoolExecutor):
        """The medial axis's pool, timing each tile's CPU in its own thread."""

        def map(self, fn, *iterables, **kwargs):
            def timed(*items):
                start = time.thread_time()
                try:
                    return fn(*items)
                finally:
                    tile_cpu.append(time.thread_time() - start)

            return super().map(timed, *iterables, **kwargs)

    tiled = "tiles" in inspect.signature(medial.medial_axis).parameters
    if tiled:
        medial.ThreadPoolExecutor = TimedPool
    sources = [(p.name, load_image(ROOT / p if not p.is_absolute() else p)[0])
               for p in (args.drawings or [Path(d) for d in DEFAULT])]
    sources += list(_tsp_images(args.tsp))
    print(f"vectorize from {Path(medial.__file__).resolve().parents[1]}; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; medians of {args.repeats}")
    print(f"{'drawing':36} {'samples':>8} {'whole wall':>10} {'cpu':>6} {'tiled wall':>10} {'cpu':>6} "
          f"{'idle':>6} {'tiles':>5}")
    for name, image in sources:
        rings, gray, level = _inputs(image, (binarize, outline_rings))
        samples = sum(len(r) for r in rings)
        row = {}
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
        for way, kwargs in (("whole", {"tiles": 1} if tiled else {}), ("tiled", {"tiles": cores})):
            if way == "tiled" and not tiled:
                continue
            medial.medial_axis(rings, gray, level, **kwargs)  # warm up
            walls, cpus, idles, counts = [], [], [], []
            for _ in range(args.repeats):
                tile_cpu.clear()
                start, start_cpu = time.perf_counter(), time.process_time()
                medial.medial_axis(rings, gray, level, **kwargs)
                walls.append(time.perf_counter() - start)
                cpus.append(time.process_time() - start_cpu)
                idles.append(cpus[-1] - sum(tile_cpu) + max(tile_cpu, default=0.0))
                counts.append(len(tile_cpu))
            row[way] = (median(walls), median(cpus), median(idles), max(counts))
        whole = row["whole"]
        line = f"{name:36} {samples:8d} {whole[0]:10.3f} {whole[1]:6.3f}"
        if "tiled" in row:
            wall, cpu, idle, count = row["tiled"]
            line += f" {wall:10.3f} {cpu:6.3f} {idle:6.3f} {count:5d}"
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
