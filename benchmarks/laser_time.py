"""Benchmark: the job-time estimate against independent models, and vector vs raster time.

Run from the repo root: `python -m benchmarks.laser_time`. For each job it prints
- estimate: machines.job_time, planner bound alone (the batch driver of machines.planner_model)
  and with the serial link and parser modelled (what `onestroke laser` prints);
- simulation: benchmarks/metrics/grbl_sim.py, written separately from GRBL's documented rules
  (literal 15-slot planner buffer, GRBL's incremental arc generator, time-stepped motion
  at 0.1 ms; shares no code with the estimator);
- length/feed: what common senders (LaserGRBL, bCNC) show.
Then the paper's Fig. 14 comparison: vector engraving vs raster engraving of the same
drawing on the same machine model.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path
from statistics import median

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from fabrication.laser.gcode_write import GcodeOptions, gcode_lines
from machines.job_time import estimate_job_time as estimate_gcode_time
from fabrication.laser.raster_time import raster_time
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import spiral_job, straight_line_job, trefoil_png
from benchmarks.metrics.grbl_sim import simulate
from machines.laser_profile import load_laser_profile

ROOT = Path(__file__).resolve().parents[1]

PROFILE = load_laser_profile()


def vectorized_drawing():
    from vectorize import VectorizeOptions, vectorize_file

    with tempfile.TemporaryDirectory() as folder:
        png = trefoil_png(Path(folder) / "trefoil.png")
        try:
            result = vectorize_file(png, VectorizeOptions())
            how = "cnn"
        except Exception:  # the CNN classifier may not be in the tree yet
            result = vectorize_file(png, VectorizeOptions(classifier="geometric"))
            how = "geometric"
    return result.drawing, how


def row(label, lines):
    start = time.perf_counter()
    job = estimate_gcode_time(lines, PROFILE)
    est_seconds = time.perf_counter() - start
    planner = job.planner_seconds
    sim = simulate(lines, max_rate=(PROFILE.max_rate_x, PROFILE.max_rate_y),
                   accel=(PROFILE.acceleration_x, PROFILE.acceleration_y),
                   junction_deviation=PROFILE.junction_deviation, arc_tolerance=PROFILE.arc_tolerance,
                   steps_per_mm=(PROFILE.steps_per_mm_x, PROFILE.steps_per_mm_y),
                   planner_blocks=PROFILE.planner_blocks)
    print(f"{label:44s} {len(lines):6d} {planner:9.3f} {sim:9.3f} {planner / sim - 1:+7.2%} "
          f"{job.total_seconds:9.3f} {job.bound:>7s} {job.naive_seconds:9.3f} ({job.naive_seconds / sim - 1:+6.1%})"
          f"  [{est_seconds * 1000:.0f} ms]")


def jobs():
    """(label, G-code lines) of every job this benchmark times (laser_estimate_vs_emulator.py too)."""
    for feed in (1500, 6000):
        yield f"long straight line 537 mm, F{feed}", straight_line_job(feed)
    for feed in (1500, 3000, 6000):
        yield f"spiral of 0.05 mm segments, F{feed}", spiral_job(feed)
    drawing, how = vectorized_drawing()
    for size, feed in ((60, 1500), (60, 3000), (20, 6000)):
        for arcs in (False, True):
            tp = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=size), arcs=arcs))
            lines = gcode_lines(tp, PROFILE, GcodeOptions(feed=float(feed)))
            yield f"vectorized trefoil ({how}) {size} mm, {'arcs' if arcs else 'lines'}, F{feed}", lines

    from vectorize import VectorizeOptions, vectorize_file

    for png in sorted((ROOT / "examples").glob("*.png")):
        try:
            example = vectorize_file(png, VectorizeOptions()).drawing
        except Exception as error:  # report and go on: the vectorizer is not under test here
            print(f"{png.name}: not vectorized ({error})")
            continue
        tp = plan_toolpath(example, PROFILE, ToolpathOptions(placement=PlacementOptions(size=60)))
        yield f"examples/{png.name} 60 mm, F3000", gcode_lines(tp, PROFILE, GcodeOptions(feed=3000.0))


def main() -> None:
    print(f"{'job':44s} {'lines':>6s} {'planner':>9s} {'simulat.':>9s} {'diff':>7s} "
          f"{'with link':>9s} {'bound':>7s} {'len/feed':>9s} (vs sim)  [estimator run time]")
    for label, lines in jobs():
        row(label, lines)
    drawing, _ = vectorized_drawing()

    print()
    print("Fig. 14 comparison (same machine model):")
    for size, feed, raster_feed, interval in ((60, 1500, 1500, 0.1), (60, 3000, 3000, 0.1),
                                              (60, 3000, 6000, 0.1), (60, 3000, 6000, 0.2), (100, 3000, 6000, 0.1)):
        tp = plan_toolpath(drawing, PROFILE, ToolpathOptions(placement=PlacementOptions(size=size)))
        vector = estimate_gcode_time(gcode_lines(tp, PROFILE, GcodeOptions(feed=float(feed))), PROFILE)
        times = []
        for _ in range(3):
            start = time.perf_counter()
            raster = raster_time(tp, PROFILE, interval=interval, feed=float(raster_feed))
            times.append(time.perf_counter() - start)
        print(f"  trefoil {size} mm: vector at F{feed} {vector.total_seconds:6.1f} s; raster at {interval} mm, "
              f"F{raster_feed}: {raster.seconds:7.1f} s ({raster.rows} rows), ratio "
              f"{raster.seconds / vector.total_seconds:5.1f}x  [raster model {median(times) * 1000:.0f} ms]")


if __name__ == "__main__":
    main()
