"""The ink's width along a fitted stroke, read from the medial axis's radii (paper 3.2: each
axis point's distance to the outline is half the local line width).

Each sample of the fitted curve takes the width (twice the radius) of a traced axis point
near it that is not uncertain (crossings, Y-feet), preferring the points the stroke itself
passed at about the same arc length: where two passes of a line lie on each other or cross,
each keeps its own width. Samples with no such point near (inside a crossing's uncertain
zone) take the widths on either side, linearly. A running median over two widths then
drops the short swells where the axis passes a junction's blob, and a Douglas-Peucker pass
(shapely) keeps only the rows the profile needs: a pen line keeps a few, a brush line one
every few widths.

The outline is traced at the binarization threshold, which sits nearer the ink's gray
than the paper's (Li's threshold on a pen drawing: 0.1-0.2): the axis's radii stop short of
the visible edge, where the gray is halfway between ink and paper (a 6 px line measured
5.3 px). `edge_offset` measures that distance once per drawing, along the outline's normals,
and the widths add it on both sides.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.ndimage import map_coordinates, median_filter
from scipy.spatial import cKDTree

from vectorize.stroke import Stroke, arc_lengths

# Samples of the fitted curve per stroke width of arc length (at least one per 2 px).
SAMPLES_PER_WIDTH = 4
# A traced point counts for a sample within this many stroke widths of it.
REACH = 2.0
# Each px of arc length between a sample and a traced point of the stroke weighs as much as
# this many px of distance: the stroke's own pass wins over another pass through the spot.
ALONG = 0.5
# Points within this many of a junction's radii measure its blob (see `ink_widths`).
JUNCTION = 2.0
# Joints turning by more than this (degrees) are corners; near one, the sides' inks merge
# over up to MERGE line widths (see `_corners`).
CORNER = 40.0
MERGE = 6.0
# Traced points weighed per sample (nearest first).
NEIGHBOURS = 8
# Running median, in stroke widths of arc length.
MEDIAN = 2.0
# Douglas-Peucker tolerance of the profile, as a fraction of the stroke width, and at least
# MIN_TOLERANCE px (the radii's own noise on the pixel grid is about 0.1 px).
TOLERANCE = 0.03
MIN_TOLERANCE = 0.2


# The edge offset is held to this fraction of the stroke width either way; it is read at
# up to EDGE_SAMPLES outline points, in steps of EDGE_STEP px.
MAX_OFFSET = 0.25
EDGE_SAMPLES = 4000
EDGE_STEP = 0.05
EDGE_CHUNK = 8  # steps read at once


def edge_offset(gray: np.ndarray, ink: np.ndarray, rings: list[np.ndarray], threshold: float,
                stroke_width: float) -> float:
    """How far (px) the visible edge of the ink lies outside its outline at `threshold`.

    gray: (H, W) in [0, 1], 1 = paper; ink: (H, W) bool, the ink; rings: the outline at
    `threshold`, (N, 2) x, y px each (`vectorize.raster.outline.outline_rings`). The visible edge
    is where the gray is halfway between the ink (its darkest 5 %) and the paper (the median
    of the rest). From up to EDGE_SAMPLES outline points, the gray (bilinear) is read along
    the normal in steps of EDGE_STEP px until it crosses that level; the median distance,
    held within MAX_OFFSET stroke widths (negative: the visible edge lies inside).
    """
    rings = [r for r in rings if len(r) >= 3]
    if not rings or not ink.any():
        return 0.0
    stride = max(1, int(np.sqrt(ink.size / 250_000)))  # levels from a quarter-million pixels at most
    dark = float(np.percentile(gray[ink], 5))
    sparse, sparse_ink = gray[::stride, ::stride], ink[::stride, ::stride]
    paper = _median_where(sparse, ~sparse_ink)
    middle = 0.5 * (dark + paper)
    if not paper > dark:
        return 0.0
    # Outline points and their normals, every so many along all rings.
    tangents = np.concatenate([np.roll(r, -1, axis=0) - np.roll(r, 1, axis=0) for r in rings])
    points = np.concatenate(rings)
    pick = np.unique(np.linspace(0, len(points) - 1, min(EDGE_SAMPLES, len(points))).astype(int))
    points, tangents = points[pick], tangents[pick]
    norm = np.linalg.norm(tangents, axis=1, keepdims=True)
    normal = np.column_stack([-tangents[:, 1], tangents[:, 0]]) / np.maximum(norm, 1e-12)

    def read(xy: np.ndarray) -> np.ndarray:
        return map_coordinates(gray, [xy[..., 1], xy[..., 0]], order=1, mode="nearest")

    # Outward: towards the paper.
    outward = np.where((read(points + 0.5 * normal) >= read(points - 0.5 * normal))[:, None], normal, -normal)
    limit = MAX_OFFSET * stroke_width
    direction = 1.0 if middle > threshold else -1.0
    steps = np.arange(0.0, limit + EDGE_STEP, EDGE_STEP)
    # The first step where the gray crosses the middle level (else the last step), read
    # EDGE_CHUNK steps at a time for the points that have not crossed yet (most cross within
    # the first few tenths of a px).
    first = np.full(len(points), len(steps) - 1)
    going = np.arange(len(points))
    for start in range(0, len(steps), EDGE_CHUNK):
        chunk = steps[start:start + EDGE_CHUNK]
        profile = read(points[going, None, :] + direction * chunk[None, :, None] * outward[going, None, :])
        crossed = profile >= middle if direction > 0 else profile <= middle
        hit = crossed.any(axis=1)
        first[going[hit]] = start + np.argmax(crossed[hit], axis=1)
        going = going[~hit]
        if not len(going):
            break
    return float(direction * np.median(steps[first]))


def _median_where(values: np.ndarray, where: np.ndarray) -> float:
    """`np.median(values[where])` (1.0 when `where` is all False), without gathering or
    sorting the values when more than half of them are the largest of all `values` (the
    paper of a clean drawing, all at one level, is brighter than the ink): then both middle
    values are that value. values, where: arrays of one shape, `where` bool."""
    count = np.count_nonzero(where)
    if not count:
        return 1.0
    top = values.max()
    if 2 * np.count_nonzero((values == top) & where) > count + 2:
        return float(top)
    return float(np.median(values[where]))


def _corners(stroke: Stroke) -> tuple[np.ndarray, np.ndarray]:
    """(points (C, 2), reach (C,)) of the joints of `stroke` where it turns by more than
    CORNER: within `reach` line widths of one the two sides' inks merge (1 / (2 sin(a / 2)),
    a the angle between the sides; at least 1/2, at most MERGE)."""
    c = stroke.control
    ends = c[:-1, 3] - c[:-1, 2]
    starts = c[1:, 1] - c[1:, 0]
    points = c[:-1, 3]
    if stroke.is_closed and len(c) > 1:
        ends, starts = np.vstack([ends, c[-1, 3] - c[-1, 2]]), np.vstack([starts, c[0, 1] - c[0, 0]])
        points = np.vstack([points, c[0, 0]])
    norm = np.linalg.norm(ends, axis=1) * np.linalg.norm(starts, axis=1)
    cos = np.einsum("ij,ij->i", ends, starts) / np.maximum(norm, 1e-12)
    turn = np.arccos(np.clip(cos, -1.0, 1.0))
    sharp = (norm > 1e-12) & (turn > np.radians(CORNER))
    between = np.pi - turn[sharp]  # the angle between the two sides
    reach = np.minimum(0.5 / np.maximum(np.sin(between / 2.0), 1e-6), MERGE)
    return points[sharp].reshape(-1, 2), np.maximum(reach, 0.5)


def _in_blobs(stroke: Stroke, xy: np.ndarray, radius: np.ndarray, usable: np.ndarray, stroke_width: float,
              junctions: np.ndarray | None) -> np.ndarray:
    """(N,) bool: the traced points whose radius measures where inks merge, not one line:
    near a junction (JUNCTION of its radii) or a corner of `stroke` (`_corners`, in widths
    of the line there), except at a spike drawn out and back, whose two passes share their
    axis points and are one line."""
    tree = cKDTree(xy)
    blob = np.zeros(len(xy), dtype=bool)
    if junctions is not None and len(junctions):
        junctions = np.asarray(junctions, dtype=float).reshape(-1, 3)
        for near in tree.query_ball_point(junctions[:, :2], JUNCTION * junctions[:, 2]):
            blob[near] = True
    corners, reach = _corners(stroke)
    if not len(corners):
        return blob
    # The traced points around each corner (all corners at once: TSP art has thousands).
    local = tree.query_ball_point(corners, 3.0 * stroke_width)
    owner = np.repeat(np.arange(len(corners)), [len(group) for group in local])
    index = np.fromiter((i for group in local for i in group), dtype=np.int64, count=len(owner))
    close = np.linalg.norm(xy[index] - corners[owner], axis=1) < stroke_width
    # Shared: another traced point lies on it. (The foot of a V is walked twice too, but its
    # points are uncertain.)
    twin, _ = tree.query(xy[index[close]], k=2) if close.any() else (np.zeros((0, 2)), None)
    shared = np.zeros(len(index))
    shared[np.flatnonzero(close)] = (twin[:, 1] == 0.0) & usable[index[close]]
    near = np.bincount(owner[close], minlength=len(corners))
    retrace = np.bincount(owner, weights=shared, minlength=len(corners)) > 0.5 * np.maximum(near, 1)
    # The line's width there: the median of the measured radii around it.
    measured = usable[index]
    owner, values = owner[measured], radius[index[measured]]
    order = np.lexsort((values, owner))
    counts = np.bincount(owner, minlength=len(corners))
    starts = np.cumsum(counts) - counts
    width = np.where(counts > 0, 2.0 * values[order][np.minimum(starts + counts // 2, max(len(values) - 1, 0))]
                     if len(values) else stroke_width, stroke_width)
    merge = ~retrace
    for group in tree.query_ball_point(corners[merge], (reach * width)[merge]):
        blob[group] = True
    return blob


def ink_widths(stroke: Stroke, xy: np.ndarray, radius: np.ndarray, certain: np.ndarray,
               stroke_width: float, edge: float = 0.0, junctions: np.ndarray | None = None) -> np.ndarray:
    """The width profile of `stroke` (px), a `Stroke.widths` array (M, 2) of rows (t, width px).

    xy: (N, 2) px, the traced axis points the stroke was fitted to, in order; radius: (N,)
    px, their distances to the outline; certain: (N,) bool, False in uncertain stretches;
    stroke_width: the drawing's measured width, px (the scale of every reach here; and the
    width of a stroke with no usable point); edge: px added to each radius (`edge_offset`);
    junctions: (J, 3) rows (x, y, radius) px of the axis's junctions: a point within
    JUNCTION radii of one measures the blob where lines meet, not a line, and is not used.
    """
    length = stroke.length
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    radius = np.asarray(radius, dtype=float).reshape(-1)
    usable = np.asarray(certain, dtype=bool) & np.isfinite(radius) & (radius > 0)
    if len(xy):
        usable &= ~_in_blobs(stroke, xy, radius, usable, stroke_width, junctions)
    if not usable.any():
        usable = np.isfinite(radius) & (radius > 0)
    if len(xy) < 2 or not usable.any() or not length > 0:
        return np.array([[0.0, stroke_width], [1.0, stroke_width]])
    arc = arc_lengths(xy)
    step = min(stroke_width / SAMPLES_PER_WIDTH, 2.0)
    # About two traced points per sample step are enough (the axis gives 3-5 per px).
    thin = np.zeros(len(xy), dtype=bool)
    thin[np.searchsorted(arc, np.arange(0.0, arc[-1], step / 2.0))] = True
    thin[-1] = True
    if (usable & thin).any():
        usable &= thin
    along = arc[usable] * (length / arc[-1]) if arc[-1] > 0 else np.zeros(int(usable.sum()))
    points, diameters = xy[usable], 2.0 * np.maximum(radius[usable] + edge, 0.0)
    count = max(2, int(np.ceil(length / step)) + 1)
    s = np.linspace(0.0, length, count)
    t = stroke.parameters_at_lengths(s)
    samples = stroke.points_at(t)
    k = min(NEIGHBOURS, len(points))
    distance, index = cKDTree(points).query(samples, k=k, distance_upper_bound=REACH * stroke_width)
    distance, index = distance.reshape(count, k), index.reshape(count, k)
    found = np.isfinite(distance)
    safe = np.where(found, index, 0)
    cost = np.where(found, distance + ALONG * np.abs(along[safe] - s[:, None]), np.inf)
    best = np.argmin(cost, axis=1)
    width = diameters[safe[np.arange(count), best]]
    hit = found[np.arange(count), best]
    if not hit.any():
        width = np.full(count, float(np.median(diameters)))
    elif not hit.all():
        width = np.interp(s, s[hit], width[hit])
    window = int(round(MEDIAN * stroke_width / step)) | 1
    if 1 < window < count:
        width = median_filter(width, size=window, mode="nearest")
    # Simplified where it is read: linear in t (the parameter is not proportional to the arc
    # length; t scaled by the length keeps both axes in px).
    tolerance = max(TOLERANCE * stroke_width, MIN_TOLERANCE)
    line = shapely.simplify(shapely.LineString(np.column_stack([t * length, width])), tolerance,
                            preserve_topology=False)
    rows = shapely.get_coordinates(line)
    rows[:, 0] /= length
    rows[0, 0], rows[-1, 0] = 0.0, 1.0
    return rows[np.concatenate([[True], np.diff(rows[:, 0]) > 0])] if len(rows) > 2 else rows
