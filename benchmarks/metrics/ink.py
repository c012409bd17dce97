"""Metrics of how faithfully an output follows the ink, beside the paper's Table 1 metrics.

- excursion: the largest distance (px) from any point of the output curves to the
  ground-truth centre line; a fit that stays in the ink keeps it within half the stroke
  width + 1 px (`EXCURSION_SLACK`);
- ink pieces: connected pieces of the ink the vectorizer was given (so "one piece of ink,
  one stroke" can be checked);
- minimum traversal length: the shortest pen path that draws every part of the ground
  truth's ink graph at least once (route inspection / Chinese postman on the graph the
  centre line forms once noded and merged), the bar for the fair-retrace rule;
- the fair-retrace rule: where the drawing order cannot be read from the ink (an ambiguous
  junction, or a ground truth that draws some stretch twice: which stretch is retraced, and
  whether the pen started at a free end, shows in no ink), an output that is one stroke,
  stays in the ink, covers it and is no longer than the minimum traversal (within
  `FAIR_LENGTH_SLACK`) counts as correct (`fair_meta` marks such ground truths);
- where the ink width changes along the line (meta "width_profile": brushes, a photo's
  perspective), the excursion bound is half the LOCAL width (at the nearest centre-line
  point) + 1 px.

docs/benchmark.md says exactly how each is measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from vectorize.drawing import Drawing
from vectorize.stroke import arc_lengths

EXCURSION_SLACK = 1.0  # px added to half the width: the acceptance bound of the excursion
CENTRE_SPACING = 0.25  # px between ground-truth centre-line samples (distance error < 0.01 px)
OUTPUT_SPACING = 0.5  # px between output samples
FAIR_LENGTH_SLACK = (0.01, 2.0)  # (share of the minimum length, stroke widths) an output may exceed it by
RETRACE_SLACK = 1.0  # px a pen path may exceed its merged ink graph by and still count as drawn once


def _samples(drawing: Drawing, spacing: float) -> np.ndarray:
    return np.concatenate([s.sample_evenly(spacing) for s in drawing.strokes])


def excursion(gt: Drawing, output: Drawing) -> float:
    """Largest distance (px) from the output's curves to the ground-truth centre line.

    The output is sampled every 0.5 px, the ground truth every 0.25 px; nan for an empty output.
    """
    if not output.strokes:
        return float("nan")
    d, _ = cKDTree(_samples(gt, CENTRE_SPACING)).query(_samples(output, OUTPUT_SPACING))
    return float(d.max())


def local_excursion(gt: Drawing, output: Drawing, profile) -> tuple[float, float, float]:
    """Excursion against a width that changes along a one-stroke `gt` (`profile`: knot
    fractions of its arc length and widths px, as benchmarks/common/render.py draws it).

    Returns the largest distance (px), the largest distance over the local width at the
    nearest centre-line point, and the smallest headroom to the local bound (half the local
    width + 1 px; negative: outside). nan for an empty output.
    """
    if not output.strokes:
        return float("nan"), float("nan"), float("nan")
    from benchmarks.common.render import profile_widths

    centre = gt.strokes[0].sample_evenly(CENTRE_SPACING)
    widths = profile_widths(profile, np.linspace(0.0, 1.0, len(centre)))
    d, nearest = cKDTree(centre).query(_samples(output, OUTPUT_SPACING))
    local = widths[nearest]
    return float(d.max()), float((d / local).max()), float((0.5 * local + EXCURSION_SLACK - d).min())


def uncovered(gt: Drawing, output: Drawing) -> float:
    """Largest distance (px) from the ground-truth centre line to the output (inf if empty)."""
    if not output.strokes:
        return float("inf")
    d, _ = cKDTree(_samples(output, CENTRE_SPACING)).query(_samples(gt, OUTPUT_SPACING))
    return float(d.max())


def excursion_bound(width: float) -> float:
    """Largest excursion (px) that still counts as inside the ink: half the width + 1 px."""
    return 0.5 * float(width) + EXCURSION_SLACK


def ink_pieces(image: np.ndarray, width: float) -> int:
    """Connected pieces (8-connected) of the pixels darker than mid-gray in `image`
    ((H, W) uint8 or float in [0, 1], light paper), ignoring dust smaller than
    max(30, 4 w^2) px."""
    gray = np.asarray(image, dtype=float)
    if gray.max() > 1.0:
        gray = gray / 255.0
    labels, count = ndimage.label(gray < 0.5, structure=np.ones((3, 3), dtype=bool))
    if count == 0:
        return 0
    areas = np.bincount(labels.ravel())[1:]
    return int(np.count_nonzero(areas >= max(30.0, 4.0 * float(width) ** 2)))


# -- route inspection on the ink graph ------------------------------------------------------------

@dataclass(frozen=True)
class InkGraph:
    """The graph a centre line forms once noded and merged (retraced parts become one edge).

    nodes: (N, 2) px; edges: (E, 2) node indices; lengths: (E,) px.
    """

    nodes: np.ndarray
    edges: np.ndarray
    lengths: np.ndarray

    @property
    def degrees(self) -> np.ndarray:
        return np.bincount(self.edges.ravel(), minlength=len(self.nodes))


def ink_graph(polyline: np.ndarray) -> InkGraph:
    """Node and merge a centre line ((N, 2) px, closed when its ends coincide) with shapely."""
    merged = shapely.line_merge(shapely.union_all(shapely.LineString(np.asarray(polyline, dtype=float))))
    parts = [p for p in shapely.get_parts(merged) if p.length > 0]
    ends = np.array([[p.coords[0], p.coords[-1]] for p in parts], dtype=float).reshape(-1, 2)
    nodes, inverse = np.unique(np.round(ends, 4), axis=0, return_inverse=True)
    return InkGraph(nodes, inverse.reshape(-1, 2), np.array([p.length for p in parts], dtype=float))


def _pairing_cost(dist: np.ndarray) -> float:
    """Minimum total distance (px) pairing all nodes, two of them allowed to stay unpaired
    (the pen's ends): a minimum-weight perfect matching (networkx's blossom) on the nodes and
    two free vertices joined to every node and to each other at no cost. Weights in integer
    thousandths of a px, where blossom is exact."""
    import networkx as nx

    k = len(dist)
    graph = nx.Graph()
    graph.add_weighted_edges_from((i, j, int(round(dist[i, j] * 1000))) for i in range(k) for j in range(i + 1, k)
                                  if np.isfinite(dist[i, j]))
    graph.add_weighted_edges_from((i, free, 0) for i in range(k) for free in ("free a", "free b"))
    graph.add_edge("free a", "free b", weight=0)
    # fsum: the matching's pairs come in an order that follows the hash seed, and a plain sum
    # of floats in another order differs in its last bit (the minimum then wobbled by 1 ULP).
    return math.fsum(float(dist[u, v]) for u, v in nx.min_weight_matching(graph)
                     if isinstance(u, int) and isinstance(v, int))


def min_traversal_length(graph: InkGraph) -> float:
    """Length (px) of the shortest pen path (one stroke, open or closed) that draws every edge
    of `graph` at least once: all edges plus the cheapest set of shortest paths pairing the
    odd-degree nodes, two of which may be the path's ends (route inspection)."""
    total = float(graph.lengths.sum())
    odd = np.flatnonzero(graph.degrees % 2 == 1)
    if len(odd) <= 2:
        return total
    n = len(graph.nodes)
    a, b = graph.edges[:, 0], graph.edges[:, 1]
    keep = a != b
    # scipy sums duplicate entries of a COO matrix: keep the shortest of parallel edges first
    order = np.argsort(-graph.lengths[keep])
    rows = np.r_[a[keep][order], b[keep][order]]
    cols = np.r_[b[keep][order], a[keep][order]]
    w = np.r_[graph.lengths[keep][order], graph.lengths[keep][order]]
    dense = np.full((n, n), np.inf)
    dense[rows, cols] = w  # later (shorter) entries win
    matrix = coo_matrix(np.where(np.isfinite(dense), dense, 0.0))
    dist = dijkstra(matrix, directed=False, indices=odd)[:, odd]
    return total + _pairing_cost(dist)


REVERSAL_DEGREES = 140.0  # the pen turns back by more than this at a retrace's tip
EXACT_PX = 0.5  # a retrace whose passes never part by more than this is already exact
MIN_REACH = 3.0  # widths from the tip a near retrace reaches at least (a sharp V's tip merges less)
MAX_PARTING = 0.5  # px the two passes of one band may part per px along it (2 sin 15 degrees)


def _at(poly: np.ndarray, s: np.ndarray, q: np.ndarray) -> np.ndarray:
    return np.c_[np.interp(q, s, poly[:, 0]), np.interp(q, s, poly[:, 1])]


def near_retraces(polyline: np.ndarray, width: float) -> list[tuple[float, float, float]]:
    """Where the pen goes out and comes back beside itself, closer than one line width all
    along (no paper between the two passes, so the ink shows one line).

    A tip is where the direction over the `width` before a point and over the `width` after it
    turn by more than `REVERSAL_DEGREES`, at the point where those two lie closest; from it the path is read at
    equal arc lengths u before and after, while the two points lie within `width` and part by
    at most `MAX_PARTING` px per px of u (beyond a retrace's base they part at the angle of
    the branches there), and reaching at least `MIN_REACH` widths. Returns
    (tip arc length, u at the last such pair, largest separation px) per tip, in path order,
    non-overlapping.
    """
    poly = np.asarray(polyline, dtype=float)
    s = arc_lengths(poly)
    w = float(width)
    step = w / 4.0
    q = np.arange(w, s[-1] - w, step)
    if len(q) < 3:
        return []
    before = _at(poly, s, q) - _at(poly, s, q - w)
    after = _at(poly, s, q + w) - _at(poly, s, q)
    cos = np.einsum("ij,ij->i", before, after) / np.maximum(
        np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1), 1e-12)
    # the tip: where the points a width before and after lie closest (zero on an exact retrace)
    gap = np.linalg.norm(_at(poly, s, q + w) - _at(poly, s, q - w), axis=1)
    tips = [k for k in range(len(q)) if cos[k] < np.cos(np.radians(REVERSAL_DEGREES))
            and gap[k] <= gap[max(k - 1, 0)] and gap[k] < gap[min(k + 1, len(q) - 1)]]
    out: list[tuple[float, float, float]] = []
    for k in tips:
        t = q[k]
        v = int(np.argmin(np.abs(s - t)))
        if abs(s[v] - t) <= step:  # the tip on the path's own vertex, where the pen turned
            t = float(s[v])
        u = np.arange(step, min(t, s[-1] - t), step)
        if not len(u):
            continue
        d = np.linalg.norm(_at(poly, s, t - u) - _at(poly, s, t + u), axis=1)
        # one band while the passes stay within a width and part slowly (under about 30
        # degrees): past a junction's base they part at the branches' angle
        apart = (d >= w) | (np.diff(d, prepend=d[0]) > MAX_PARTING * step)
        n = int(np.argmax(apart)) if np.any(apart) else len(d)
        if n == 0 or u[n - 1] < MIN_REACH * w or (out and t - u[n - 1] < out[-1][0] + out[-1][1]):
            continue
        out.append((float(t), float(u[n - 1]), float(d[:n].max())))
    return out


def snap_near_retraces(polyline: np.ndarray, width: float) -> np.ndarray:
    """The pen path with each near retrace (`near_retraces`) made exact: the way back follows
    the way out, then steps (less than a width) across to where the real way back leaves the
    merged band. Retraces already exact are left as they are."""
    poly = np.asarray(polyline, dtype=float)
    s = arc_lengths(poly)
    pieces, cursor = [poly[:1]], 0.0
    for t, u, sep in near_retraces(poly, width):
        if sep <= EXACT_PX:
            continue
        # the way out cut at t - u, so that the way back runs over the very same points
        out = np.vstack([_at(poly, s, np.array([t - u])), poly[(s > t - u) & (s < t)], _at(poly, s, np.array([t]))])
        pieces += [poly[(s > cursor) & (s < t - u)], out, out[::-1][1:], _at(poly, s, np.array([t + u]))]
        cursor = t + u
    if len(pieces) == 1:
        return poly
    return np.vstack(pieces + [poly[s > cursor]])


def fair_meta(polyline: np.ndarray, *, ambiguous: bool = False, scale: float = 1.0,
              near_width: float | None = None) -> dict:
    """The fair-retrace facts of a ground-truth pen path ((N, 2) px, exact where it retraces).

    Returns meta entries: "retraced_length" (px the path draws beyond its merged ink graph,
    i.e. the length it draws twice), "fair" (True when `ambiguous` or the path retraces more
    than `RETRACE_SLACK`: then which stretch is drawn twice, or whether the pen started at a
    free end, cannot be read from the ink), "fair_why" ("ambiguous", "retrace" or "") and,
    "odd_nodes" (odd-degree junctions of the graph), "route_min" (the minimum traversal, px, times `scale`: a handwriting word's graph is taken
    before jitter and scaled to the jittered length) and, when fair, the same as "min_length"
    (the fair-retrace rule's bar). near_width (px, a glyph's
    line width): also count a near retrace (`near_retraces`: out and back closer than the line
    is wide) as a retrace, on the path `snap_near_retraces` makes (fair_why "near-retrace").
    """
    poly = np.asarray(polyline, dtype=float)
    graph = ink_graph(poly)
    retraced = float(arc_lengths(poly)[-1] - graph.lengths.sum())
    why = "ambiguous" if ambiguous else ("retrace" if retraced > RETRACE_SLACK else "")
    if near_width is not None and why != "ambiguous":
        snapped = snap_near_retraces(poly, near_width)
        if snapped is not poly:
            near_graph = ink_graph(snapped)
            near = float(arc_lengths(snapped)[-1] - near_graph.lengths.sum())
            if near > retraced + RETRACE_SLACK:
                graph, retraced, why = near_graph, near, "near-retrace"
    route_min = min_traversal_length(graph) * scale
    meta: dict = {"retraced_length": retraced, "fair": False, "fair_why": "", "route_min": route_min,
                  "odd_nodes": int(np.count_nonzero(graph.degrees % 2))}
    if why:
        meta.update(fair=True, fair_why=why, min_length=route_min)
    return meta


# -- per-drawing ink scores ----------------------------------------------------------------------

@dataclass(frozen=True)
class InkScores:
    """excursion: px (nan without output); excursion_widths: the same over the stroke width
    (over the local width where it varies); within: excursion <= half the (local) width + 1 px; uncovered: px of ground truth farthest from the
    output; fair_ok: the fair-retrace rule's geometric part holds (one stroke, in the ink,
    covering it, no longer than the minimum traversal)."""

    excursion: float
    excursion_widths: float
    within: bool
    uncovered: float
    fair_ok: bool
    headroom: float = float("nan")


def fair_length_limit(min_length: float, width: float) -> float:
    """Longest output (px) that retraces no more than the minimum: 1 % + 2 widths of slack for
    fitting (rounded corners, cusps a little short or long)."""
    share, widths = FAIR_LENGTH_SLACK
    return min_length * (1.0 + share) + widths * float(width)


def ink_scores(gt, output: Drawing, cover_tolerance: float) -> InkScores:
    """Ink scores of `output` against a `GroundTruth` `gt`, given the distance (px) within which
    the ground truth counts as covered."""
    width = gt.drawing.stroke_width
    profile = gt.meta.get("width_profile")
    if profile is None:
        exc = excursion(gt.drawing, output)
        exc_w, headroom = exc / width, excursion_bound(width) - exc
    else:  # the bound follows the local width (brushes, perspective)
        exc, exc_w, headroom = local_excursion(gt.drawing, output, profile)
    within = bool(headroom >= 0.0)
    unc = uncovered(gt.drawing, output)
    min_length = gt.meta.get("min_length")
    fair = bool(len(output.strokes) == 1 and within and unc <= cover_tolerance and min_length is not None
                and output.length <= fair_length_limit(min_length, width))
    return InkScores(exc, exc_w if np.isfinite(exc) else float("nan"), within, unc, fair,
                     headroom if np.isfinite(exc) else float("nan"))


def verdict(gt, scores, ink: InkScores) -> bool:
    """Whether an output counts as correct: one stroke in the ground-truth order by the order
    score (`scores`, a metrics.Scores), or, for a fair ground truth (meta "fair"), the
    fair-retrace rule: `ink.fair_ok` (one stroke, in the ink, covering it, at the minimum
    length) and every ground-truth crossing matched (a wrong turn at a crossing draws the same
    ink at the same length, but turns the crossing into a touch)."""
    return bool(scores.correct or (gt.meta.get("fair") and ink.fair_ok and scores.undetected == 0))
