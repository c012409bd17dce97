"""Embroidery quality, measured on files written and read back with pyembroidery.

Run from the repository root: python benchmarks/embroidery_quality.py
Prints the numbers the acceptance criteria of issue 4 ask for (worst cases over the
test designs, every style and format).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from embroidery_fixtures import FORMATS, STYLE_NAMES, design, lock_figure_ok, spiral, stroke_rows  # noqa: E402
from fabrication.embroidery.export import write_embroidery  # noqa: E402
from fabrication.embroidery.needles import BODY, LOCK, TACK, UNDERLAY  # noqa: E402
from fabrication.embroidery.plan import STITCH, PlanOptions, plan_embroidery, style_options  # noqa: E402
from fabrication.embroidery.read import read_embroidery  # noqa: E402
from fabrication.embroidery.stats import embroidery_stats  # noqa: E402
from fabrication.embroidery.zigzag import ZigzagOptions  # noqa: E402
from machines.hoops import hoop_named  # noqa: E402
from vectorize.drawing import Drawing  # noqa: E402
from vectorize.stroke import Stroke  # noqa: E402


def seg_dist(p, a, b):
    ab = b - a
    u = np.clip(((p - a) @ ab) / max(ab @ ab, 1e-12), 0, 1)
    return np.linalg.norm(p - (a + u[:, None] * ab), axis=1)


def main() -> None:
    folder = tempfile.mkdtemp()
    hoop = hoop_named("100x100")
    drawing = design()
    worst_err = worst_axis = 0.0
    shortest_body, shortest_any = np.inf, np.inf
    locks_ok = inside = True
    for style in STYLE_NAMES:
        plan = plan_embroidery(drawing, PlanOptions(style=style_options(style)))
        rows = stroke_rows(plan)
        for ext in FORMATS:
            path = f"{folder}/q_{style}.{ext}"
            write_embroidery(plan, path)
            back = read_embroidery(path).plan
            a = plan.points[plan.kinds == STITCH]
            b = back.points[back.kinds == STITCH]
            worst_err = max(worst_err, float(np.abs(a - b).max()))
            s0, s1 = back.stitches()
            d = s1 - s0
            worst_axis = max(worst_axis, float(np.abs(d).max()))
            lengths = np.hypot(*d.T)
            roles = plan.roles[np.flatnonzero(plan.stitch_mask)]
            shortest_any = min(shortest_any, float(lengths.min()))
            shortest_body = min(shortest_body, float(lengths[~np.isin(roles, (TACK, LOCK))].min()))
            inside &= hoop.contains(back.bounds())
            index = {r: i for i, r in enumerate(np.flatnonzero(plan.kinds == STITCH))}
            for r in rows.values():
                f, l = index[r[0]], index[r[-1]]
                locks_ok &= lock_figure_ok(b[f:f + 5]) and lock_figure_ok(b[l - 4:l + 1])
    print(f"read back vs planned needle points, worst         {worst_err:.3f} mm  (all {len(STYLE_NAMES)} styles x {len(FORMATS)} formats)")
    print(f"longest needle-down stitch per axis               {worst_axis:.2f} mm")
    print(f"shortest stitch outside locks / anywhere           {shortest_body:.2f} mm / {shortest_any:.2f} mm")
    print(f"every stroke starts with a tack and ends in a lock {locks_ok}")
    print(f"design inside the 100x100 hoop                     {inside}")

    # Running stitch: chord to curve, and corners.
    plan = plan_embroidery(drawing, PlanOptions(style=style_options("running")))
    worst = 0.0
    for k, r in stroke_rows(plan).items():
        body = r[4:len(r) - 4]
        t = plan.params[body] - k
        pts = plan.points[body]
        for i in range(len(body) - 1):
            curve = drawing.strokes[k].points_at(np.linspace(t[i], t[i + 1], 64))
            worst = max(worst, float(seg_dist(curve, pts[i], pts[i + 1]).max()))
    corner = np.array([35.0, -20.0])
    needles = plan.points[plan.kinds == STITCH]
    print(f"running: worst chord-to-curve distance             {worst:.3f} mm  (tolerance 0.2)")
    print(f"running: needle point to the 120-degree corner     {np.linalg.norm(needles - corner, axis=1).min():.3f} mm")

    # Zigzag on straight lines at several angles.
    width_err, spacing_means = [], []
    for angle in (0, 30, 90, 137):
        u = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
        n = np.array([-u[1], u[0]])
        line = Drawing((Stroke.from_polyline(np.array([-15 * u, 15 * u])),), 30, 30, "mm")
        plan = plan_embroidery(line, PlanOptions(style=ZigzagOptions(width=2.0, pull_compensation=0.2)))
        body = plan.points[(plan.kinds == STITCH) & (plan.roles == BODY)]
        mid = body[np.abs(body @ u) < 13]
        width_err.append(float(np.abs(np.abs(np.diff(mid @ n)) - 2.2).max()))
        spacing_means.append(float(np.abs((mid[2:] - mid[:-2]) @ u).mean()))
    print(f"zigzag: worst |width - (2.0 + 0.2)| on straights  {max(width_err):.3f} mm")
    print(f"zigzag: mean peak-to-peak spacing (0.4 asked)      {min(spacing_means):.3f} .. {max(spacing_means):.3f} mm")
    gaps = []
    for radius in (1.5, 2.0, 3.0, 5.0):
        for width in (2.0, 3.0):
            arc = Drawing((spiral(0, 0, radius, radius, 0.75, n=12),), 20, 20, "mm")
            plan = plan_embroidery(arc, PlanOptions(style=ZigzagOptions(width=width)))
            pts = plan.points[(plan.kinds == STITCH) & np.isin(plan.roles, (BODY, UNDERLAY))]
            d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
            np.fill_diagonal(d, np.inf)
            gaps.append(float(d.min()))
    print(f"zigzag: closest two needle points on inner curves  {min(gaps):.3f} mm  (radius 1.5-5 mm, width 2-3 mm)")
    stats = embroidery_stats(plan_embroidery(drawing, PlanOptions(style=style_options("zigzag"))))
    print("zigzag design stats: " + "; ".join(line.split(None, 1)[0] + " " + line.split(None, 1)[1].strip()
                                              for line in stats.lines()))


if __name__ == "__main__":
    main()
