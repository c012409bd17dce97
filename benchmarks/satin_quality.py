"""Satin quality: the column's width against the drawn width on drawings whose line swells
and thins, and the corner drawings of embroidery_quality.py.

Run from the repository root: python -m benchmarks.satin_quality [--count 6] [--size 90] [--arcs]
(also part of python -m benchmarks.embroidery_quality). The varying-width set is the
vectorizer benchmark's brush kana (pressure, tapered ends) and broad-nib capitals (marker-
like: thick and thin by direction), rendered with their known width profiles
(benchmarks/sets/brush.py), vectorized, placed at --size mm and sewn with `--style satin`. Per
drawing: the share of the column's length whose sewn width (benchmarks/metrics/columns.py)
lies within 10 % or 0.2 mm of the drawn width x the design's scale (the acceptance of
issue 27), over the length where the stroke's ink is its own (where two passes of the line
share ink, a V's sides or a crossing, one pass's width cannot be seen: that share is shown);
density with every needle point counted and repeated holes (fabrication.embroidery.quality),
slits (metrics.columns.slits), and needle points planned per second. --arcs adds satin on
arcs of 0.3-3 mm radius at 1-6 mm width (`tight_arcs`): where the column is wider than its
bend, whether each dense place and repeated hole is warned about.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np
from scipy.spatial import cKDTree

from benchmarks.sets.brush import capital_set, kana_set
from benchmarks.metrics.columns import sewn_widths, shared_ground, slits
from benchmarks.common.render import profile_widths, render_truth, to_uint8
from fabrication.embroidery.plan import STITCH, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.quality import needle_density, repeated_holes
from fabrication.placement import PlacementOptions, place
from vectorize.drawing import Drawing
from vectorize.pipeline import vectorize_image
from vectorize.stroke import Stroke


CORNER_ANGLES = (30, 45, 60, 90, 120, 150, 170)


def corner_drawing(angle: float, leg: float = 12.0, width: float = 2.0) -> Drawing:
    """Two straight legs (mm) meeting at `angle` degrees between them (180: straight on),
    ink `width` mm wide."""
    turn = np.radians(180.0 - angle)
    stroke = Stroke.from_polyline(np.array([[-leg, 0.0], [0.0, 0.0], [leg * np.cos(turn), leg * np.sin(turn)]]))
    return Drawing((stroke,), 2 * leg, 2 * leg, "mm", width)


def column_slits(plan, style) -> int:
    """Slit places of every stroke of a satin or zigzag plan (a zigzag's width is constant)."""
    found = 0
    for k, stroke in enumerate(plan.sewn.strokes):
        if hasattr(style, "sewn_width"):
            profile = stroke.widths if stroke.widths is not None else np.array([[0.0, 1.0], [1.0, 1.0]])
            from fabrication.embroidery.sampling import dense_curve

            curve = dense_curve(stroke)

            def half_at(s, curve=curve, profile=profile):
                return style.sewn_width(np.interp(curve.t_at(s), profile[:, 0], profile[:, 1])) / 2.0
            inset = style.short_stitch_inset  # a share of the width
        else:
            def half_at(s):
                return np.full(len(s), style.reach)
            inset = style.short_stitch_inset / 2.0  # a share of the reach
        # the short stitches' jagged edge inside bends is by design: probed inside it
        found += len(slits(plan, k, half_at, style.spacing, inset=2.0 * inset))
    return found


def width_check(gt, size: float, style) -> dict:
    """Vectorize, place and sew one varying-width drawing; its figures (module doc)."""
    drawing = vectorize_image(to_uint8(render_truth(gt))).drawing
    placed = place(drawing, PlacementOptions(size=size))
    scale = placed.stroke_width / drawing.stroke_width
    x0, y0, x1, y1 = drawing.bounds()
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    start = time.perf_counter()
    plan = plan_embroidery(placed, PlanOptions(style=style))
    seconds = time.perf_counter() - start
    dense = gt.drawing.strokes[0].sample_evenly(0.25)
    fraction = np.linspace(0.0, 1.0, len(dense))
    tree = cKDTree(dense)
    good = own_total = total = 0
    for k in range(len(plan.sewn.strokes)):
        s, where, width = sewn_widths(plan, k)
        _, i = tree.query(where / scale + centre)  # the drawn line's nearest point, px
        drawn = profile_widths(gt.meta["width_profile"], fraction[i]) * scale
        own = ~shared_ground(s, where, drawn / 2.0)
        ok = np.abs(width - drawn) <= np.maximum(0.1 * drawn, 0.2)
        good += int(np.sum(ok & own))
        own_total += int(own.sum())
        total += len(s)
    needles = plan.points[plan.kinds == STITCH]
    return dict(name=gt.name, width=gt.drawing.stroke_width * scale, ok=good / max(own_total, 1),
                measured=own_total / max(total, 1), density=needle_density(needles).maximum,
                holes=len(repeated_holes(plan)), slits=column_slits(plan, style), rate=len(needles) / seconds)


def varying_width(count: int = 6, size: float = 90.0, seed: int = 0) -> list[dict]:
    """The varying-width set's figures: `count` brush kana and `count` broad-nib capitals."""
    style = style_options("satin")
    rows = [width_check(gt, size, style) for gt in kana_set(count, seed) + capital_set(count, seed)]
    print(f"\n{'drawing (satin, ' + format(size, 'g') + ' mm)':36} {'W mm':>5} {'width ok':>8} {'measured':>8} "
          f"{'density':>7} {'holes':>5} {'slits':>5} {'needles/s':>9}")
    for r in rows:
        print(f"{r['name']:36} {r['width']:5.2f} {100 * r['ok']:7.1f}% {100 * r['measured']:7.1f}% {r['density']:7d} "
              f"{r['holes']:5d} {r['slits']:5d} {r['rate']:9.0f}")
    print(f"width within 10 % or 0.2 mm of the drawn width x scale: median {100 * statistics.median(r['ok'] for r in rows):.1f} %"
          f" of the length, worst {100 * min(r['ok'] for r in rows):.1f} % ({sum(r['ok'] >= 0.95 for r in rows)} of "
          f"{len(rows)} drawings at 95 % or more); worst density {max(r['density'] for r in rows)}, repeated holes "
          f"{sum(r['holes'] for r in rows)}, slits {sum(r['slits'] for r in rows)}")
    return rows


ARC_RADII = (0.3, 0.5, 0.8, 1.2, 2.0, 3.0)  # mm
ARC_WIDTHS = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)  # mm
ARC_SWEEPS = (90, 180, 270, 360)  # degrees


def tight_arcs() -> list[dict]:
    """Satin of every width in ARC_WIDTHS on arcs of every radius and sweep above, through the
    whole job (`embroider`, as embroidery_quality.py): density, repeated holes, whether the
    warnings name each place, and slits where the arc is wider than the column's half width
    (on a tighter one the column's inside is held short of the centre by design, and the
    band the slit measure probes passes it). Arcs shorter than --min-stroke are refused."""
    from fabrication.embroidery.pipeline import EmbroideryJob, embroider
    from fabrication.embroidery.quality import DENSITY_LIMIT, hole_places
    from machines.hoops import hoop_named
    from onestroke.errors import InputError

    rows = []
    for radius in ARC_RADII:
        for width in ARC_WIDTHS:
            for sweep in ARC_SWEEPS:
                angle = np.radians(np.linspace(0.0, sweep, sweep // 5 + 1))
                stroke = Stroke.from_polyline(radius * np.c_[np.cos(angle), np.sin(angle)])
                style = style_options("satin", width=width)
                job = EmbroideryJob(placement=PlacementOptions(size=2 * radius), hoop=hoop_named("200x200"),
                                    plan=PlanOptions(style=style))
                try:
                    result = embroider(Drawing((stroke,), 2 * radius, 2 * radius, "mm", width), job)
                except InputError:
                    continue
                plan = result.plan
                density = needle_density(plan.points[plan.kinds == STITCH])
                holes = repeated_holes(plan)
                said = " ".join(result.warnings)
                spots = hole_places(plan, holes)
                named = (all(str(p) in said for p in density.places) or f"at {len(density.places)} places" in said) \
                    and (all(str(p) in said for p in spots) or f"at {len(spots)} places" in said)
                over = density.maximum > DENSITY_LIMIT or len(holes) > 0
                rows.append(dict(radius=radius, width=width, sweep=sweep, density=density.maximum, holes=len(holes),
                                 unwarned=over and not named,
                                 slits=column_slits(plan, style) if radius > width / 2 else None))
    print(f"\nsatin on arcs (radius {', '.join(map(str, ARC_RADII))} mm x width {', '.join(map(str, ARC_WIDTHS))} mm"
          f" x sweep {', '.join(map(str, ARC_SWEEPS))} degrees; {len(rows)} sewn, the rest shorter than --min-stroke)")
    print(f"{'radius vs half width':22} {'cases':>5} {'over 6':>6} {'worst':>5} {'with holes':>10} {'unwarned':>8} "
          f"{'with slits':>10}")
    for label, test in (("radius > half width", lambda r: r["radius"] > r["width"] / 2),
                        ("radius <= half width", lambda r: r["radius"] <= r["width"] / 2)):
        part = [r for r in rows if test(r)]
        cut = [r["slits"] for r in part if r["slits"] is not None]
        print(f"{label:22} {len(part):5d} {sum(r['density'] > 6 for r in part):6d} "
              f"{max((r['density'] for r in part), default=0):5d} {sum(r['holes'] > 0 for r in part):10d} "
              f"{sum(r['unwarned'] for r in part):8d} {(str(sum(c > 0 for c in cut)) if cut else '-'):>10}")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=6, help="drawings of each kind (default 6)")
    parser.add_argument("--size", type=float, default=90.0, help="design size, mm (default 90)")
    parser.add_argument("--arcs", action="store_true", help="also satin on tight arcs (radius 0.3-3 mm, width 1-6 mm)")
    args = parser.parse_args()
    varying_width(args.count, args.size)
    if args.arcs:
        tight_arcs()


if __name__ == "__main__":
    main()
