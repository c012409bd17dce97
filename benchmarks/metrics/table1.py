"""Metrics of the vectorizer benchmark (paper, Section 4.1 and Table 1, plus a drawing-order score).

Per drawing, comparing a ground-truth `Drawing` (one stroke) with the vectorizer's output:

- SSIM and PSNR (skimage.metrics) between the input render and the output re-rendered at
  the same canvas size and the ground-truth stroke width;
- length ratio |L_out - L_gt| / L_gt and stroke count;
- intersections: every self-intersection of all curves, between strokes too, found with
  shapely on flattened polylines and classified topologically (a crossing is a point where
  the two passes alternate around it; a point where one pass stays on one side of the other
  is a touch and is not an intersection); ground truth and output are matched one-to-one
  within 5 px. Output intersections inside "don't-care" zones (within max(5 px, width) of a
  ground-truth touch, near-touch or retraced part such as an out-and-back spike) are neither
  matched nor hallucinated: there the ground truth has no crossing, the two passes of the
  output lie on top of each other and cross numerically at random; the order score judges
  those places instead (a crossing within 5 px of its partner on the other side counts as
  matched even when only one of the two lies in such a zone: `match_outside_dont_care`);
- order score: the fraction of the drawing that the output visits in the ground truth's
  sequence (see `order_score`); "correct order" = one stroke and order score >= ORDER_THRESHOLD.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

MATCH_DISTANCE = 5.0  # px, paper Section 4.1
ORDER_THRESHOLD = 0.98
FLATTEN_TOLERANCE = 0.05  # px


# -- self-intersections -----------------------------------------------------------------------

@dataclass(frozen=True)
class Intersections:
    """Contacts between passes of polylines.

    crossings: (C, 2) points where two passes cross; crossing_angles: (C,) degrees in (0, 90];
    touches: (T, 2) points where two passes meet without crossing; retraces: list of shapely
    geometries where a polyline runs over itself (collinear overlaps and the junctions where
    such a retrace starts); multiple: (Q, 2) points where three or more passes meet.
    """

    crossings: np.ndarray
    crossing_angles: np.ndarray
    touches: np.ndarray
    retraces: list
    multiple: np.ndarray


def _angle_in_arc(x: np.ndarray, start: float, end: float) -> bool:
    """Whether angle x lies strictly inside the counter-clockwise arc from start to end."""
    span = (end - start) % (2 * np.pi)
    offset = (x - start) % (2 * np.pi)
    return 0.0 < offset < span


def polyline_intersections(polylines: Sequence[np.ndarray], closed: Sequence[bool] | None = None) -> Intersections:
    """All contacts between passes of the polylines (each (N, 2)), including self-contacts.

    A polyline is closed when `closed[k]` is true (its last vertex equals its first).
    Contacts where a pass starts or ends (an open end lying on another pass) are ignored.
    """
    if closed is None:
        closed = [bool(len(p) > 2 and np.allclose(p[0], p[-1])) for p in polylines]
    a_list, b_list, poly_id, edge_idx = [], [], [], []
    cleaned = []
    for k, p in enumerate(polylines):
        p = np.asarray(p, dtype=float)
        keep = np.ones(len(p), dtype=bool)
        keep[1:] = np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-9
        p = p[keep]
        cleaned.append(p)
        if len(p) < 2:
            continue
        n = len(p) - 1
        a_list.append(p[:-1])
        b_list.append(p[1:])
        poly_id.append(np.full(n, k))
        edge_idx.append(np.arange(n))
    empty = Intersections(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), [], np.zeros((0, 2)))
    if not a_list:
        return empty
    a = np.concatenate(a_list)
    b = np.concatenate(b_list)
    pid = np.concatenate(poly_id)
    eid = np.concatenate(edge_idx)
    nedges = np.array([len(p) - 1 for p in cleaned])
    offsets = np.concatenate([[0], np.cumsum(np.maximum(nedges, 0))])
    segs = shapely.linestrings(np.stack([a, b], axis=1))
    tree = shapely.STRtree(segs)
    i, j = tree.query(segs, predicate="intersects")
    sel = i < j
    i, j = i[sel], j[sel]
    same = pid[i] == pid[j]
    adjacent = same & (eid[j] - eid[i] == 1)
    closed_arr = np.array([bool(c) for c in closed] + [False])
    wrap = same & closed_arr[pid[i]] & (eid[i] == 0) & (eid[j] == nedges[pid[i]] - 1)
    keep = ~(adjacent | wrap)
    i, j = i[keep], j[keep]
    if len(i) == 0:
        return empty
    geoms = shapely.intersection(segs[i], segs[j])
    types = shapely.get_type_id(geoms)
    retraces = list(geoms[types == 1])
    is_point = types == 0
    i, j, geoms = i[is_point], j[is_point], geoms[is_point]
    if len(i) == 0:
        return Intersections(empty.crossings, empty.crossing_angles, empty.touches, retraces, empty.multiple)
    pts = shapely.get_coordinates(geoms)
    d = b - a
    lengths = np.linalg.norm(d, axis=1)
    unit = d / lengths[:, None]

    def pass_of(edge: np.ndarray, p: np.ndarray):
        """(polyline, position, in-direction or None, out-direction or None) per row."""
        frac = np.einsum("ij,ij->i", p - a[edge], unit[edge]) / lengths[edge]
        return frac

    frac_i = pass_of(i, pts)
    frac_j = pass_of(j, pts)

    # Cluster coincident points (a vertex contact is reported by several edge pairs).
    if len(pts) > 1:
        pairs = cKDTree(pts).query_pairs(1e-3, output_type="ndarray")
    else:
        pairs = np.zeros((0, 2), dtype=int)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(pts), len(pts)))
    ncl, label = connected_components(graph, directed=False)

    eps = 1e-7
    crossings, angles, touches, multiple = [], [], [], []
    for c in range(ncl):
        rows = np.flatnonzero(label == c)
        passes = {}
        for r in rows:
            for edge, frac in ((i[r], frac_i[r]), (j[r], frac_j[r])):
                k = int(pid[edge])
                e = int(eid[edge])
                n = int(nedges[k])
                if frac >= 1 - eps:
                    e, frac = e + 1, 0.0
                    if e == n:
                        if closed_arr[k]:
                            e = 0
                        else:
                            passes[(k, n, 0)] = None  # the open end of polyline k
                            continue
                if frac <= eps:
                    key = (k, e, 0)
                    prev = e - 1
                    if prev < 0:
                        prev = n - 1 if closed_arr[k] else None
                    out_dir = unit[offsets[k] + e]
                    in_dir = None if prev is None else -unit[offsets[k] + prev]
                    passes[key] = None if in_dir is None else (in_dir, out_dir)
                else:
                    key = (k, e, round(float(frac), 6))
                    passes[key] = (-unit[offsets[k] + e], unit[offsets[k] + e])
        point = pts[rows].mean(axis=0)
        values = list(passes.values())
        if any(v is None for v in values):
            continue  # an end lying on a pass: not an intersection
        if len(values) >= 3:
            multiple.append(point)
            continue
        if len(values) != 2:
            continue
        (in1, out1), (in2, out2) = values
        ang = [float(np.arctan2(v[1], v[0])) for v in (in1, out1, in2, out2)]
        dirs = np.array([in1, out1, in2, out2])
        cos = dirs @ dirs.T
        if np.any(cos[np.triu_indices(4, 1)] > 1 - 1e-9):
            retraces.append(shapely.Point(point))  # two passes leave along the same line
            continue
        side_c = _angle_in_arc(ang[2], ang[0], ang[1])
        side_d = _angle_in_arc(ang[3], ang[0], ang[1])
        if side_c != side_d:
            crossings.append(point)
            # angle between the two passes' lines, from their through-directions
            t1 = out1 - in1
            t2 = out2 - in2
            cosang = abs(np.dot(t1, t2)) / (np.linalg.norm(t1) * np.linalg.norm(t2))
            angles.append(float(np.degrees(np.arccos(np.clip(cosang, 0.0, 1.0)))))
        else:
            touches.append(point)
    as_pts = lambda x: np.array(x, dtype=float).reshape(-1, 2)  # noqa: E731
    return Intersections(as_pts(crossings), np.array(angles, dtype=float), as_pts(touches), retraces,
                         as_pts(multiple))


def ambiguous_junctions(polyline: np.ndarray) -> int:
    """Junctions where the drawing order cannot be read from the ink.

    The polyline is noded and merged with shapely into the graph a vectorizer sees (retraced
    parts collapse into one edge). At a junction of odd degree (a Y: one pass plus a part
    drawn out and back) the retraced branch is the one ending free; when two or more
    branches end free there, any of them could have been the retraced one.
    """
    merged = shapely.line_merge(shapely.union_all(shapely.LineString(polyline)))
    parts = shapely.get_parts(merged)
    if len(parts) == 0:
        return 0
    ends = np.array([[p.coords[0], p.coords[-1]] for p in parts]).reshape(-1, 2)
    _keys, inverse, counts = np.unique(np.round(ends, 4), axis=0, return_inverse=True, return_counts=True)
    idx = inverse.reshape(-1, 2)
    free_edges = np.zeros(len(counts), dtype=int)
    for a, b in idx:
        if a != b:
            if counts[b] == 1:
                free_edges[a] += 1
            if counts[a] == 1:
                free_edges[b] += 1
    odd = (counts >= 3) & (counts % 2 == 1)
    return int(np.count_nonzero(odd & (free_edges >= 2)))


def close_passes(stroke: Stroke, closed: bool, width: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where two passes of `stroke` come within one width of each other.

    Returns the centre-line samples (every width/4): their arc lengths s (N,) and points
    (N, 2), and the index pairs (P, 2) of samples closer than `width` that are more than 3
    widths apart along the line (around it, for a closed one).
    """
    w = float(width)
    s = np.linspace(0, stroke.length, max(2, int(np.ceil(stroke.length / (w / 4)))) + 1)
    if closed:
        s = s[:-1]
    pts = stroke.points_at_lengths(s)
    pairs = cKDTree(pts).query_pairs(w, output_type="ndarray")
    sep = np.abs(s[pairs[:, 0]] - s[pairs[:, 1]])
    if closed:
        sep = np.minimum(sep, stroke.length - sep)
    return s, pts, pairs[sep > 3 * w]


def merged_clusters(stroke: Stroke, closed: bool, width: float) -> list[np.ndarray]:
    """The places where two passes of `stroke` run within one width of each other, each as
    the (K, 2) centre-line samples involved (`close_passes`), one array per connected place."""
    w = float(width)
    spacing = w / 4
    _, pts, pairs = close_passes(stroke, closed, w)
    if len(pairs) == 0:
        return []
    idx = np.unique(pairs)
    cp = pts[idx]
    near = cKDTree(cp).query_pairs(2.0 * spacing, output_type="ndarray")
    graph = coo_matrix((np.ones(len(near)), (near[:, 0], near[:, 1])), shape=(len(cp), len(cp)))
    ncl, label = connected_components(graph, directed=False)
    return [cp[label == c] for c in range(ncl)]


def merged_without_crossing(stroke: Stroke, closed: bool, width: float, crossings: np.ndarray) -> list:
    """Places where two passes of `stroke` run within one width of each other (their ink
    merges) and that hold no crossing: near-retraces, narrow wedges, a pass grazing another.

    Returns shapely MultiPoints of the centre-line samples involved (`close_passes`).
    """
    w = float(width)
    crossings = np.asarray(crossings, dtype=float).reshape(-1, 2)
    zones = []
    for cluster in merged_clusters(stroke, closed, w):
        if len(crossings) and np.min(np.linalg.norm(cluster[:, None] - crossings[None], axis=2)) <= w:
            continue
        zones.append(shapely.MultiPoint(cluster))
    return zones


def hidden_crossings(stroke: Stroke, closed: bool, width: float, crossings: np.ndarray,
                     angles: np.ndarray) -> list:
    """Crossings no ink can show: two passes that run within one width of each other far
    beyond the crossing's own ink-merge zone (a near-retrace whose return pass crosses the
    outward one at its base, as some font outlines draw it a unit off).

    A crossing at angle a merges the passes over about w / sin(a/2) around it; a merged place
    holding the crossing and reaching more than 2 widths beyond that hides it. Returns shapely
    Points of the hidden crossings.
    """
    w = float(width)
    crossings = np.asarray(crossings, dtype=float).reshape(-1, 2)
    hidden = []
    for cluster in merged_clusters(stroke, closed, w):
        for p, a in zip(crossings, np.asarray(angles, dtype=float)):
            reach = np.linalg.norm(cluster - p, axis=1)
            if reach.min() <= w and reach.max() > w / max(np.sin(np.radians(a) / 2), 1e-3) + 2 * w:
                hidden.append(shapely.Point(*p))
    return hidden


def tiny_loop_crossings(stroke: Stroke, closed: bool, width: float, crossings: np.ndarray) -> list:
    """Crossings whose loop is too small to leave paper inside it: no ink can show them.

    A pen path that crosses itself encloses a loop between its two passes; a loop whose centre
    line is L px long spans at most L / pi px, so with a line `width` px wide it holds no hole
    (nothing tells the crossing from a blot or a corner) unless L > pi * width. Jittered corners
    make such loops (a mouse trace's samples overshoot a sharp turn by a pixel or two and come
    back across it). The loop's length is the arc between the passes through the crossing
    (samples within 1 px of it). Returns shapely Points of those crossings.
    """
    w = float(width)
    spacing = 0.25
    points = stroke.sample_evenly(spacing)
    tiny = []
    for p in np.asarray(crossings, dtype=float).reshape(-1, 2):
        near = np.flatnonzero(np.linalg.norm(points - p, axis=1) <= 1.0)
        if not len(near):
            continue
        runs = np.split(near, np.flatnonzero(np.diff(near) > 1) + 1)
        centres = np.array([run.mean() for run in runs]) * spacing
        if len(runs) == 1:
            loop = float((runs[0][-1] - runs[0][0]) * spacing)  # both passes within the same 1 px
        else:
            loops = np.diff(centres)
            if closed:
                loops = np.append(loops, len(points) * spacing - centres[-1] + centres[0])
            loop = float(loops.min())
        if loop < np.pi * w:
            tiny.append(shapely.Point(*p))
    return tiny


def drawing_polylines(drawing: Drawing, tolerance: float = FLATTEN_TOLERANCE) -> tuple[list[np.ndarray], list[bool]]:
    """Flattened strokes and whether each is closed."""
    polys = [s.flatten(tolerance) for s in drawing.strokes]
    return polys, [s.is_closed for s in drawing.strokes]


def matched_pairs(gt: np.ndarray, out: np.ndarray, distance: float = MATCH_DISTANCE) -> list[tuple[int, int]]:
    """The best one-to-one matching of points closer than `distance`: (gt index, out index) pairs."""
    gt = np.asarray(gt, dtype=float).reshape(-1, 2)
    out = np.asarray(out, dtype=float).reshape(-1, 2)
    if len(gt) == 0 or len(out) == 0:
        return []
    d = np.linalg.norm(gt[:, None, :] - out[None, :, :], axis=2)
    cost = np.where(d <= distance, d, 1e6)
    r, c = linear_sum_assignment(cost)
    return [(int(i), int(j)) for i, j in zip(r, c) if d[i, j] <= distance]


# -- drawing order ------------------------------------------------------------------------------

def _longest_chain(first: np.ndarray, second: np.ndarray) -> int:
    """Longest chain of pairs, strictly increasing in `first`, non-decreasing in `second`."""
    if len(first) == 0:
        return 0
    order = np.lexsort((-second, first))
    tails: list[int] = []
    for v in second[order].tolist():
        k = bisect_right(tails, v)
        if k == len(tails):
            tails.append(v)
        else:
            tails[k] = v
    return len(tails)


def _coverage(gt: np.ndarray, out: np.ndarray, tol: float, tree: cKDTree) -> float:
    """min(GT coverage, output coverage) of monotone alignments within `tol`."""
    lists = tree.query_ball_point(gt, tol)
    counts = np.fromiter((len(x) for x in lists), dtype=int, count=len(lists))
    if counts.sum() == 0:
        return 0.0
    gi = np.repeat(np.arange(len(gt)), counts)
    oj = np.fromiter((v for x in lists for v in x), dtype=int, count=int(counts.sum()))
    g = _longest_chain(gi, oj) / len(gt)
    o = _longest_chain(oj, gi) / len(out)
    return min(g, o)


def order_score(gt: Stroke, output: Sequence[Stroke], tol: float, closed: bool | None = None) -> float:
    """How much of the drawing the output visits in the ground-truth sequence, in [0, 1].

    Both curves are sampled every tol/2 of arc length (the output's strokes concatenated in
    their order). A sample pair "agrees" when the points are within `tol`. The score is the
    smaller of two fractions: GT samples on the longest alignment that advances along both
    curves (strictly along the GT, never backwards along the output), and output samples on
    the longest alignment that advances strictly along the output. A wrong turn at a touch or
    a crossing either splits the curve (the second stroke cannot continue the alignment) or
    runs a whole loop backwards (a reversed loop cannot be aligned monotonically), so the
    loop's share of the length is lost. The output may run the whole curve in reverse, and for
    a closed ground truth it may start anywhere: the best of these alignments counts.
    """
    if closed is None:
        closed = gt.is_closed
    if not output:
        return 0.0
    spacing = tol / 2.0
    g = gt.sample_evenly(spacing)
    if closed:
        g = g[:-1]
    o = np.concatenate([s.sample_evenly(spacing) for s in output])
    best = 0.0
    for cand in (o, o[::-1]):
        tree = cKDTree(cand)
        if closed:
            shifts = _cyclic_starts(g, cand[0], tol)
        else:
            shifts = [0]
        for shift in shifts:
            best = max(best, _coverage(np.roll(g, -shift, axis=0), cand, tol, tree))
            if best >= 1.0:
                return best
    return best


def _cyclic_starts(g: np.ndarray, start: np.ndarray, tol: float, limit: int = 6) -> list[int]:
    """GT indices where a closed curve could start to meet the output's first point."""
    d = np.linalg.norm(g - start, axis=1)
    near = d <= tol
    if not near.any():
        return [int(np.argmin(d))]
    idx = np.flatnonzero(near)
    # split into cyclic runs of consecutive indices, best point of each run
    breaks = np.flatnonzero(np.diff(idx) > 1)
    runs = np.split(idx, breaks + 1)
    if len(runs) > 1 and runs[0][0] == 0 and runs[-1][-1] == len(g) - 1:
        runs[0] = np.concatenate([runs[-1], runs[0]])
        runs.pop()
    best = sorted((float(d[r].min()), int(r[np.argmin(d[r])])) for r in runs)
    return [k for _, k in best[:limit]]


# -- per-drawing evaluation ---------------------------------------------------------------------

@dataclass(frozen=True)
class Scores:
    ssim: float
    psnr: float
    length_ratio: float
    stroke_count: int
    gt_intersections: int
    out_intersections: int
    matched: int
    order: float

    @property
    def undetected(self) -> int:
        return self.gt_intersections - self.matched

    @property
    def hallucinated(self) -> int:
        return self.out_intersections - self.matched

    @property
    def correct(self) -> bool:
        """One stroke, in the ground-truth order."""
        return self.stroke_count == 1 and self.order >= ORDER_THRESHOLD


def dont_care_mask(points: np.ndarray, zones: Sequence, radius: float) -> np.ndarray:
    """Which points lie within `radius` of any zone geometry (or (2,) point): exact distances,
    through an STRtree (buffering long zones of centre-line samples and uniting them took
    seconds per drawing on long lines)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points) == 0 or not zones:
        return np.zeros(len(points), dtype=bool)
    geoms = [z if isinstance(z, shapely.Geometry) else shapely.Point(*np.asarray(z, dtype=float)) for z in zones]
    near = shapely.STRtree(geoms).query(shapely.points(points), predicate="dwithin", distance=radius)
    mask = np.zeros(len(points), dtype=bool)
    mask[near[0]] = True
    return mask


def match_outside_dont_care(gt_pts: np.ndarray, out_pts: np.ndarray, zones: Sequence,
                            radius: float) -> tuple[int, int, int]:
    """(ground-truth crossings counted, output crossings counted, matched) with don't-care zones.

    Points within `radius` px of a zone are left out on both sides and the rest matched within
    MATCH_DISTANCE. A crossing left out on one side only because it lies just inside the zone's
    reach while its partner lies just outside (an output crossing 1 px from the true one, 4.6
    and 5.3 px from a touch) is the same crossing: such pairs, found among the points the first
    matching left over, count as matched on both sides. That only ever adds matches, so no
    drawing scores lower than with the zones applied to each side alone.
    """
    gt_pts = np.asarray(gt_pts, dtype=float).reshape(-1, 2)
    out_pts = np.asarray(out_pts, dtype=float).reshape(-1, 2)
    gt_zone, out_zone = dont_care_mask(gt_pts, zones, radius), dont_care_mask(out_pts, zones, radius)
    gt_kept, out_kept = gt_pts[~gt_zone], out_pts[~out_zone]
    pairs = matched_pairs(gt_kept, out_kept)
    gt_left = np.delete(gt_kept, [i for i, _ in pairs], axis=0)
    out_left = np.delete(out_kept, [j for _, j in pairs], axis=0)
    true_found_in_zone = len(matched_pairs(gt_left, out_pts[out_zone]))  # true crossing outside
    output_true_in_zone = len(matched_pairs(gt_pts[gt_zone], out_left))  # output crossing outside
    return (len(gt_kept) + output_true_in_zone, len(out_kept) + true_found_in_zone,
            len(pairs) + true_found_in_zone + output_true_in_zone)


def evaluate(gt, output: Drawing, gt_image: np.ndarray | None = None) -> Scores:
    """Scores of `output` (a Drawing in the GT's px frame) against `gt` (a `GroundTruth`).

    gt_image: the input render (gray float, 1 = paper); rendered here when omitted.
    """
    from benchmarks.common.render import render

    width = gt.drawing.stroke_width
    if gt_image is None:
        gt_image = render(gt.drawing)
    out_image = render(output, stroke_width=width, size=(gt_image.shape[1], gt_image.shape[0]))
    ssim = float(structural_similarity(gt_image, out_image, data_range=1.0))
    psnr = float(peak_signal_noise_ratio(gt_image, out_image, data_range=1.0)) if not np.array_equal(
        gt_image, out_image) else float("inf")
    l_gt = gt.drawing.length
    l_out = output.length
    polys, closed = drawing_polylines(output)
    inter = polyline_intersections(polys, closed)
    out_pts = np.vstack([inter.crossings, inter.multiple])
    gt_pts = np.asarray(gt.intersections, dtype=float).reshape(-1, 2)
    gt_count, out_count, matched = match_outside_dont_care(gt_pts, out_pts, gt.dont_care,
                                                           max(MATCH_DISTANCE, width))
    tol = order_tolerance(width)
    order = order_score(gt.drawing.strokes[0], output.strokes, tol, closed=gt.closed) if output.strokes else 0.0
    return Scores(ssim=ssim, psnr=psnr, length_ratio=abs(l_out - l_gt) / l_gt,
                  stroke_count=len(output.strokes), gt_intersections=gt_count,
                  out_intersections=out_count, matched=matched, order=float(order))


def order_tolerance(stroke_width: float) -> float:
    """Distance within which output and ground truth agree for the order score (px)."""
    return max(3.0, float(stroke_width))
