"""Benchmark: planning and writing a laser job of ~100,000 G-code moves.

Run from the repo root: `python benchmarks/laser_plan.py`. Prints medians of 5 runs for
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

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fabrication.laser import toolpath as toolpath_module  # noqa: E402
from fabrication.laser.gcode_write import GcodeOptions, gcode_lines, write_gcode  # noqa: E402
from fabrication.laser.job_time import estimate_gcode_time  # noqa: E402
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath  # noqa: E402
from fabrication.placement import PlacementOptions, place  # noqa: E402
from machines.laser_profile import load_laser_profile  # noqa: E402
from vectorize.drawing import Drawing  # noqa: E402
from vectorize.stroke import Stroke  # noqa: E402


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


def analytic_bounds(stroke: Stroke) -> tuple[float, float, float, float]:
    """Exact bounds of a cubic spline: end points and the roots of its derivative per axis.

    A proposal for `Stroke.bounds` (vectorize/stroke.py samples 48 points per segment,
    which is what makes `place()` slow on long strokes); measured below, not installed.
    """
    control = stroke.control
    p0, p1, p2, p3 = (control[:, i] for i in range(4))
    a = -p0 + 3 * p1 - 3 * p2 + p3  # derivative / 3 = a t^2 + 2 b t + c, per axis
    b = p0 - 2 * p1 + p2
    c = p1 - p0
    disc = b * b - a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = np.abs(a) < 1e-12
        ts = np.stack([np.where(linear, -c / (2 * b), (-b + sq) / a), np.where(linear, np.nan, (-b - sq) / a)], -1)
    ok = (ts > 0) & (ts < 1) & (disc[..., None] >= 0)
    t = np.where(ok, ts, 0.0)
    u = 1 - t
    vals = u**3 * p0[..., None] + 3 * u * u * t * p1[..., None] + 3 * u * t * t * p2[..., None] + t**3 * p3[..., None]
    vals = np.where(ok, vals, p0[..., None])
    lo = np.minimum(np.minimum(p0, p3).min(axis=0), vals.min(axis=(0, 2)))
    hi = np.maximum(np.maximum(p0, p3).max(axis=0), vals.max(axis=(0, 2)))
    return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


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
        # the whole job again with Stroke.bounds computed analytically (proposal, see above)
        real_bounds = Stroke.bounds
        Stroke.bounds = analytic_bounds
        try:
            t_fast, tp_fast = timed(lambda: plan_toolpath(drawing, profile, options))
        finally:
            Stroke.bounds = real_bounds
        assert tp_fast.segment_count == tp.segment_count
        print(f"{strokes} stroke(s) of {100_000 // strokes} Bezier segments -> {tp.segment_count} G-code moves, "
              f"{len(lines)} lines (medians of 5 runs):")
        print(f"  place() (fabrication/placement.py)          {t_place:7.3f} s")
        print(f"  laser planning without place()              {t_own:7.3f} s  (flatten, simplify, order)")
        print(f"  G-code lines                                {t_lines:7.3f} s")
        print(f"  atomic write                                {t_write:7.3f} s")
        print(f"  planning + writing, laser code              {t_own + t_lines + t_write:7.3f} s")
        print(f"  planning + writing, with place()            {t_plan + t_lines + t_write:7.3f} s")
        print(f"  planning + writing, analytic Stroke.bounds  {t_fast + t_lines + t_write:7.3f} s  (proposal, not installed)")
        print(f"  time estimate (GRBL planner model)          {t_est:7.3f} s  -> job {job.total_seconds:.0f} s")
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from laser_fixtures import wiggle_drawing

    smooth = place(wiggle_drawing(20000), PlacementOptions(size=380))
    for arcs in (False, True):
        t, tp = timed(lambda: plan_toolpath(smooth, profile, ToolpathOptions(arcs=arcs)), runs=3)
        arc_count = sum(int((p.kinds != 1).sum()) for p in tp.paths)
        print(f"smooth stroke of 20,000 Bezier segments, arcs={arcs}: plan_toolpath {t:.3f} s, "
              f"{tp.segment_count} moves ({arc_count} arcs)")


if __name__ == "__main__":
    main()
