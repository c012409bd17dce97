"""The burned path stays within the tolerance of the input curve, measured both ways, arcs included."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from laser_fixtures import parse_gcode
from fabrication.laser.gcode_write import GcodeOptions, gcode_lines
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import hershey_text_drawing, rose_drawing, trefoil_png, wiggle_drawing
from machines.laser_profile import load_laser_profile

PROFILE = load_laser_profile()


def _burn_polylines(lines) -> list[np.ndarray]:
    """Each stroke's burned path from the G-code, arcs sampled every 0.002 rad."""
    moves = parse_gcode(lines)
    out, current = [], []
    for k in range(len(moves)):
        if not moves.laser_on[k]:
            if current:
                out.append(np.vstack(current))
                current = []
            continue
        a, b, c = moves.start[k], moves.end[k], moves.centre[k]
        if not current:
            current.append(a[None])
        if moves.kind[k] >= 2:
            t0, t1 = np.arctan2(*(a - c)[::-1]), np.arctan2(*(b - c)[::-1])
            if moves.kind[k] == 3:
                t1 = t1 + 2 * np.pi if t1 <= t0 else t1
            else:
                t1 = t1 - 2 * np.pi if t1 >= t0 else t1
            t = np.linspace(t0, t1, max(3, int(abs(t1 - t0) / 0.002)))[1:]
            r = np.linspace(np.hypot(*(a - c)), np.hypot(*(b - c)), len(t) + 1)[1:]
            current.append(c + r[:, None] * np.c_[np.cos(t), np.sin(t)])
        else:
            current.append(b[None])
    if current:
        out.append(np.vstack(current))
    return out


def _densify(poly: np.ndarray, spacing: float) -> np.ndarray:
    seg = np.diff(poly, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(*seg.T) / spacing).astype(int))
    idx = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    return np.vstack([poly[idx] + seg[idx] * frac[:, None], poly[-1:]])


def _one_way(points: np.ndarray, polylines: list[np.ndarray]) -> float:
    """Largest distance from `points` to the nearest segment of `polylines` (exact, GEOS)."""
    segs = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in polylines])
    tree = shapely.STRtree(shapely.linestrings(segs))
    _, dist = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    return float(dist.max())


def measured_deviation(toolpath, lines, spacing: float = 0.002) -> tuple[float, float]:
    """(burned -> curve, curve -> burned) largest distances, mm. The curve is sampled with
    400 points per Bézier segment; the burned path every `spacing` mm."""
    burned = _burn_polylines(lines)
    curves = [c.points_at(np.linspace(0, 1, 400 * c.segment_count + 1)) for c in toolpath.curves]
    burned_pts = np.vstack([_densify(p, spacing) for p in burned])
    curve_pts = np.vstack([_densify(p, spacing) for p in curves])
    return _one_way(burned_pts, curves), _one_way(curve_pts, burned)


CASES = [
    ("rose", 0.02, False), ("rose", 0.02, True), ("text", 0.02, False), ("text", 0.05, True),
    ("wiggle", 0.02, True), ("vectorized", 0.02, False), ("vectorized", 0.02, True),
    ("vectorized", 0.1, True),
]


@pytest.fixture(scope="module")
def drawings(tmp_path_factory):
    from vectorize import VectorizeOptions, vectorize_file

    png = trefoil_png(tmp_path_factory.mktemp("png") / "trefoil.png")
    vectorized = vectorize_file(png, VectorizeOptions(classifier="geometric")).drawing
    return {"rose": rose_drawing(), "text": hershey_text_drawing("laser"), "wiggle": wiggle_drawing(80),
            "vectorized": vectorized}


@pytest.mark.parametrize("name,tolerance,arcs", CASES)
def test_burned_path_within_tolerance(drawings, name, tolerance, arcs, record_property):
    size = 25 if name == "wiggle" else 60  # the wiggle is long: keep the measurement quick
    tp = plan_toolpath(drawings[name], PROFILE, ToolpathOptions(placement=PlacementOptions(size=size),
                                                                tolerance=tolerance, arcs=arcs))
    lines = gcode_lines(tp, PROFILE, GcodeOptions())
    to_curve, to_burn = measured_deviation(tp, lines)
    record_property("deviation_mm", (to_curve, to_burn))
    print(f"{name} tol {tolerance} arcs {arcs}: burned->curve {to_curve:.4f} mm, curve->burned {to_burn:.4f} mm, "
          f"{tp.segment_count} moves")
    assert to_curve <= tolerance and to_burn <= tolerance
    if name != "text":  # Hershey text is polylines already: nothing to flatten
        # not trivially: the path uses its budget (it is not flattened far finer than asked)
        assert max(to_curve, to_burn) > tolerance / 2


def test_arcs_cut_the_line_count(drawings):
    common = dict(placement=PlacementOptions(size=60), tolerance=0.02)
    lines_only = plan_toolpath(drawings["vectorized"], PROFILE, ToolpathOptions(**common))
    with_arcs = plan_toolpath(drawings["vectorized"], PROFILE, ToolpathOptions(arcs=True, **common))
    assert with_arcs.segment_count < 0.6 * lines_only.segment_count
