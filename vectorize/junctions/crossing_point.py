"""Where the two passes through a degree-4 node cross: the point the image classifier looks at.

At a shallow crossing the two strokes' inks merge over a long band, and simplification
merges the band's two medial-axis junctions into one node at the middle of the band
(`simplify._merge`). The middle of the band is the crossing only when the crossing is
symmetric: where one pass curves more than the other, the node sits up to a width off the
true crossing, and a crop centred there shows two strokes running side by side (a touch)
instead of two strokes swapping sides. The classifier was trained on crossings cropped
within ~0.6 widths of the true point (`vectorize.training.synth`), so the crop is centred
on an estimate of the crossing made from the geometry alone: each straight-through pass
(`intersections.crossing_pairing`) is fitted with a parabola to its two branches just
outside the merged ink, and the crop goes where the two parabolas cross (or come closest). The move
is bounded by the merged ink (and by the 3 widths along a touch's contact that the
training's touch crops range over), so a touch, whose "passes" meet anywhere along the
contact, still gets a crop like those it was trained on.
"""

from __future__ import annotations

import numpy as np

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import slots
from vectorize.junctions.intersections import crossing_pairing

# The fit window along each branch, in stroke widths beyond the merged ink (the node's
# span): past the first width, where the medial axis bends into the junction, and short
# enough that a quadratic follows a curving stroke.
WINDOW = (1.0, 4.0)
# The fit's samples along each branch, in stroke widths (the outline's densest spacing).
FIT_STEP = 1.0 / 8.0
# Samples of the second pass (the crossing is interpolated between two of them).
SAMPLES = 200
# Largest move along a touch's contact that the classifier's training crops include (widths).
MAX_SHIFT = 3.0


def _window(graph: MedialGraph, slot: tuple[int, str], lo: float, hi: float, step: float) -> np.ndarray:
    """The slot's branch between `lo` and `hi` px of arc from the node, every `step` px: (K, 2).

    Evenly by arc length, not the branch's own points: the medial axis has a point per
    Voronoi vertex, dense along curves and sparse along straight sides (`outline_rings`'
    `sparse`), and a least-squares fit to its points would weigh the curves more.
    """
    bid, end = slot
    branch = graph.branches[bid]
    points, arc = (branch.points, branch.arc) if end == "a" else (branch.points[::-1], branch.arc_back)
    at = np.arange(lo, min(hi, float(arc[-1])) + 1e-9, step)
    return np.column_stack([np.interp(at, arc, points[:, 0]), np.interp(at, arc, points[:, 1])])


def _pass_fit(centre: np.ndarray, first: np.ndarray, second: np.ndarray):
    """A parabola through both sides of one pass: (axis, normal, coefficients, x range), or None.

    The frame (origin `centre`) has its x axis from one side's points to the other's, so
    y(x) is single valued for any pass that turns by less than ~90 degrees over the window.
    """
    axis = second.mean(axis=0) - first.mean(axis=0)
    norm = float(np.hypot(*axis))
    if norm < 1e-9:
        return None
    axis /= norm
    normal = np.array([-axis[1], axis[0]])
    pts = np.vstack([first, second]) - centre
    x, y = pts @ axis, pts @ normal
    return axis, normal, np.polyfit(x, y, 2), (float(x.min()), float(x.max()))


def crossing_point(graph: MedialGraph, node: int, dirs: np.ndarray, stroke_width: float) -> np.ndarray:
    """Estimated crossing point (2,) px of the two straight-through passes at a degree-4 node.

    dirs: (4, 2) the node's branch directions in `slots` order (`simplify.directions`).
    Falls back to the node's position where a branch is too short to fit (another node
    within the window) or the fit is degenerate.
    """
    if len(dirs) != 4:
        return np.asarray(graph.positions[node], dtype=float)
    return passes_crossing(graph, node, crossing_pairing(dirs), stroke_width)


def passes_crossing(graph: MedialGraph, node: int, passes, stroke_width: float,
                    window: tuple[float, float] | None = None) -> np.ndarray:
    """Estimated point (2,) px where two passes through `node` cross (passes: two slot
    pairs, indices into `slots`), fitted as in `crossing_point` on each branch between
    `window` stroke widths beyond the node's span (None: `WINDOW`); the node's position
    where a branch is too short to fit or the fit is degenerate."""
    centre = np.asarray(graph.positions[node], dtype=float)
    span = graph.spans.get(node, 0.0)
    node_slots = slots(graph, node)
    lo, hi = (span + f * stroke_width for f in (WINDOW if window is None else window))
    windows = {i: _window(graph, node_slots[i], lo, hi, FIT_STEP * stroke_width) for pair in passes for i in pair}
    if min(len(p) for p in windows.values()) < 3:
        return centre
    fits = [_pass_fit(centre, windows[a], windows[b]) for a, b in passes]
    if fits[0] is None or fits[1] is None:
        return centre
    # The second pass sampled, then measured across the first pass's parabola (in its frame):
    # the sign of the offset flips where they cross; without a flip (a touch, or passes
    # that meet beyond the fits) the closest approach is taken.
    (axis, normal, coef, (x0, x1)), (axis2, normal2, coef2, (u0, u1)) = fits
    us = np.linspace(u0, u1, SAMPLES)
    samples = centre + us[:, None] * axis2 + np.polyval(coef2, us)[:, None] * normal2
    x, y = (samples - centre) @ axis, (samples - centre) @ normal
    inside = (x >= x0) & (x <= x1)
    if not inside.any():
        return centre
    offset = y - np.polyval(coef, x)
    flips = np.flatnonzero(inside[:-1] & inside[1:] & (np.sign(offset[:-1]) != np.sign(offset[1:])))
    if len(flips):
        # Where the passes cross more than once (a loop), the crossing nearest the node.
        t = offset[flips] / (offset[flips] - offset[flips + 1])
        points = samples[flips] + t[:, None] * (samples[flips + 1] - samples[flips])
        point = points[int(np.argmin(np.hypot(*(points - centre).T)))]
    else:
        k = int(np.flatnonzero(inside)[np.argmin(np.abs(offset[inside]))])
        point = samples[k] - 0.5 * offset[k] * normal
    # Stay in the merged ink: the crossing lies within it.
    offset = point - centre
    reach = min(span + 0.5 * stroke_width, MAX_SHIFT * stroke_width)
    dist = float(np.hypot(*offset))
    if dist > reach:
        point = centre + offset * (reach / dist)
    return point
