"""Benchmark: planning and writing a laser job of ~100,000 G-code moves.

Run from the repo root: `python -m benchmarks.laser_plan`. Prints medians of 5 runs for
each stage: placement (fabrication.placement.place, not laser code), flattening +
simplification + ordering (plan_toolpath minus placement), G-code formatting, the atomic
write, and the time estimate (reported separately: it is not part of writing).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path
from statistics import median

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np


from fabrication.laser import toolpath as toolpath_module
from fabrication.laser.gcode_write import GcodeOptions, gcode_lines, write_gcode
from machines.job_time import estimate_job_time as estimate_gcode_time
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions, place
from machines.laser_profile import load_laser_profile
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def jagged_drawing(n_points: int, strokes: int, seed: int = 0) -> Drawing:
    """`strokes` random-walk polylines (sharp turns every step, so nothing simplifies away)."""
    rng = np.random.default_rng(seed)
    per = n_points // strokes
    out = []
    for k in range(strokes):
        angle = np.cumsum(rng.uniform(-2.0, 2.0, per))
        steps = np.c_[np.cos(angle), np.sin(angle)] * 2.0
        pts = np.cumsum(steps, axis=0) + rng.uniform(0, 2000, 2)
        out.append(Stroke.from_polyline(pts))
    return Drawing(tuple(out), 3000, 3000, "px", 2.0)


def timed(fn, runs=5):
    times, result = [], None
    for _ in range(runs):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return median(times), result


def main() -> None:
    profile = load_laser_profile()
    for strokes in (1, 200):
        drawing = jagged_drawing(100_001, strokes)
        options = ToolpathOptions(placement=PlacementOptions(size=380))
        t_place, placed = timed(lambda: place(drawing, options.placement))
        t_plan, tp = timed(lambda: plan_toolpath(drawing, profile, options))
        # the laser planner's own work: the same call with place() answered from a cache
        real_place = toolpath_module.place
        toolpath_module.place = lambda d, o: placed
        try:
            t_own, tp_own = timed(lambda: plan_toolpath(drawing, profile, options))
        finally:
            toolpath_module.place = real_place
        assert tp_own.segment_count == tp.segment_count
        t_lines, lines = timed(lambda: gcode_lines(tp, profile, GcodeOptions()))
        with tempfile.TemporaryDirectory() as folder:
            t_write, _ = timed(lambda: write_gcode(Path(folder) / "job.gcode", lines))
        t_est, job = timed(lambda: estimate_gcode_time(lines, profile), runs=3)
        print(f"{strokes} stroke(s) of {100_000 // strokes} Bezier segments -> {tp.segment_count} G-code moves, "
              f"{len(lines)} lines (medians of 5 runs):")
        print(f"  place() (fabrication/placement.py)          {t_place:7.3f} s")
        print(f"  laser planning without place()              {t_own:7.3f} s  (flatten, simplify, order)")
        print(f"  G-code lines                                {t_lines:7.3f} s")
        print(f"  atomic write                                {t_write:7.3f} s")
        print(f"  planning + writing, laser code              {t_own + t_lines + t_write:7.3f} s")
        print(f"  planning + writing, with place()            {t_plan + t_lines + t_write:7.3f} s")
        print(f"  time estimate (GRBL planner model)          {t_est:7.3f} s  -> job {job.total_seconds:.0f} s")
    from benchmarks.sets.laser_jobs import wiggle_drawing

    smooth = place(wiggle_drawing(20000), PlacementOptions(size=380))
    for arcs in (False, True):
        t, tp = timed(lambda: plan_toolpath(smooth, profile, ToolpathOptions(arcs=arcs)), runs=3)
        arc_count = sum(int((p.kinds != 1).sum()) for p in tp.paths)
        print(f"smooth stroke of 20,000 Bezier segments, arcs={arcs}: plan_toolpath {t:.3f} s, "
              f"{tp.segment_count} moves ({arc_count} arcs)")


if __name__ == "__main__":
    main()
