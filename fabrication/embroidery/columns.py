"""Columns across a stroke: where satin and zigzag needle points go, corners included.

A stroke is cut into columns at its corners (a turn sharper than `corner_angle` within a
column's half width). Each column is a run of rows across the curve: a centre point, the
normal there (the chord over +-half a width: a fan on gentle bends) and a half width to
either side, the inside one held below the bend's radius. Rows are spaced so that the
LONGER rail gets one row every half `spacing` (Ink/Stitch's rule: the outside of a bend is
never sparser than asked; the inside crowds and gets short stitches).

Corners (Ink/Stitch's stroke-to-satin joins them with the path's line join, mitred up to a
mitre limit): a corner whose mitre stays within `mitre_limit` half widths of the corner point
is mitred, the column before it running on to the mitre line and the one after starting
there; a sharper one is split: the column before ends at the corner and the column after
starts with a round cap that runs in by its half width ahead of the corner, covering the
corner's round outside (a round pen's tip) on top, so no remnant of the column before
shows beyond the tip. In both, the rows
of the column before that lie under the column after are cut back to `overlap` inside its
edge: each place is covered once, with no gap between the two (no slit) and no second
layer (no pile-up). A column cut away entirely (a spike drawn out and back) is sewn by the
next one alone.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.spatial import cKDTree

from fabrication.embroidery.quality import DENSITY_RADIUS
from fabrication.embroidery.sampling import DenseCurve
from onestroke.ranges import Range
from vectorize.stroke import Stroke

# Corner controls, shared by the satin and zigzag options.
CORNER_ANGLE = Range(10.0, 170.0, unit="degrees", name="--corner-angle")
MITRE_LIMIT = Range(1.0, 10.0, name="--mitre-limit")
OVERLAP = Range(0.0, 2.0, unit="mm", name="--corner-overlap")
# The inside half width stays below this fraction of the bend's radius, so inner points
# never pass the centre of curvature (they would sew loops and run backwards).
MAX_INNER_REACH = 0.75
# How far inside a column (mm) its end rows take their tangent.
END_INSIDE = 1e-3
# Fine samples per half spacing when rows are placed (the rails' lengths are measured on them).
FINE = 4
# A row cut back to less than this (mm) outside the column sewn over it is left out.
MIN_PIECE = 0.5
# Columns within this many half widths of a corner are cut back under the later ones.
CLUSTER = 4.0
# A rail point with more rail points of other rows than this within DENSITY_RADIUS (the
# rails alone: underlay, tacks and locks may add one or two) has a row too many.
CROWDED = 4
# ... and one is left out only where the rows either side of it lie within this share of
# the spacing of each other on both rails (the threads either side then still cover it).
THIN_GAP = 0.75


@dataclass(frozen=True, eq=False)
class Rows:
    """Rows across one column, in sewing order. centre (N, 2) mm; normal (N, 2) unit, to
    the left of the direction of travel; left / right (N,) mm from the centre to each rail
    (pull compensation included); t (N,) the stroke's parameter (rows that run on past a
    corner keep the corner's); s (N,) arc length mm along the stroke (likewise clamped);
    full (N, 2) mm: the left and right reach from the centre before the rows were cut back
    under a later column (None: not cut), how far a cut end may run on under it."""

    centre: np.ndarray
    normal: np.ndarray
    left: np.ndarray
    right: np.ndarray
    t: np.ndarray
    s: np.ndarray
    full: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.centre)

    @property
    def left_points(self) -> np.ndarray:
        return self.centre + self.normal * self.left[:, None]

    @property
    def right_points(self) -> np.ndarray:
        return self.centre - self.normal * self.right[:, None]

    @property
    def reach(self) -> np.ndarray:
        """(N, 2) the left and right reach before any cut (`full`, or left and right)."""
        return self.full if self.full is not None else np.column_stack([self.left, self.right])

    def take(self, index) -> "Rows":
        return Rows(self.centre[index], self.normal[index], self.left[index], self.right[index], self.t[index],
                    self.s[index], None if self.full is None else self.full[index])

    def recentred(self, index: np.ndarray, mid: np.ndarray, left: np.ndarray, right: np.ndarray) -> "Rows":
        """These rows with rows `index` cut: their centres moved by `mid` (mm along the
        normal) and their reach now `left` / `right`; the reach before the cut is kept."""
        centre, new_left, new_right, full = self.centre.copy(), self.left.copy(), self.right.copy(), self.reach.copy()
        centre[index] += self.normal[index] * mid[:, None]
        new_left[index], new_right[index] = left, right
        full[index, 0] -= mid
        full[index, 1] += mid
        return Rows(centre, self.normal, new_left, new_right, self.t, self.s, full)

    @staticmethod
    def concat(parts: "list[Rows]") -> "Rows":
        fields = ("centre", "normal", "left", "right", "t", "s")
        full = None if all(p.full is None for p in parts) else np.concatenate([p.reach for p in parts])
        return Rows(*(np.concatenate([getattr(p, f) for p in parts]) for f in fields), full)


@dataclass(frozen=True, eq=False)
class Column:
    """One column: its rows (after corner cutting), and the arc lengths (mm) of the stroke it
    covers, [start, end] (runs on past corners not included)."""

    rows: Rows
    start: float
    end: float


@dataclass(frozen=True)
class Corner:
    """A corner of a stroke at arc length s (mm): point (2,), incoming and outgoing unit
    directions, turn (radians, 0 = straight on, pi = straight back), left: True when it
    turns left (towards the normal)."""

    s: float
    point: np.ndarray
    incoming: np.ndarray
    outgoing: np.ndarray
    turn: float
    left: bool


def find_corners(stroke: Stroke, curve: DenseCurve, half: np.ndarray, angle: float) -> list[Corner]:
    """Corners of `stroke` sharper than `angle` (degrees), away from the ends: where the chords
    over the half width `half` (M,) mm (at the curve's dense points) before and after a point
    turn by more than that. The sharpest first; then each further one measured with chords
    that stop at the corners already found (a corner's own turn does not make its
    neighbours corners), at least a quarter half width each."""
    s, length = curve.s, curve.length
    reach = np.maximum(half, 0.05)
    inside = (s > reach) & (s < length - reach)
    if not inside.any():
        return []
    turn, d_in, d_out = _turns(stroke, curve, s, np.clip(s - reach, 0.0, length), np.clip(s + reach, 0.0, length))
    turn = np.where(inside, turn, 0.0)
    candidates = np.flatnonzero(turn > np.radians(angle))
    corners: list[Corner] = []
    taken: list[float] = []  # arc lengths of the corners found, sorted
    for i in candidates[np.argsort(-turn[candidates], kind="stable")].tolist():
        k = bisect.bisect_left(taken, s[i])
        lo = max(s[i] - reach[i], taken[k - 1] if k > 0 else 0.0)
        hi = min(s[i] + reach[i], taken[k] if k < len(taken) else length)
        if min(s[i] - lo, hi - s[i]) < 0.25 * reach[i]:
            continue
        if lo > s[i] - reach[i] or hi < s[i] + reach[i]:
            clipped, a, b = _turns(stroke, curve, s[i:i + 1], np.array([lo]), np.array([hi]))
            if clipped[0] <= np.radians(angle):
                continue
            d_in[i], d_out[i], turn[i] = a[0], b[0], clipped[0]
        taken.insert(k, float(s[i]))
        cross = d_in[i, 0] * d_out[i, 1] - d_in[i, 1] * d_out[i, 0]
        corners.append(Corner(float(s[i]), curve.points[i].copy(), d_in[i].copy(), d_out[i].copy(),
                              float(turn[i]), bool(cross > 0)))
    return sorted(corners, key=lambda c: c.s)


def _turns(stroke: Stroke, curve: DenseCurve, s: np.ndarray, before: np.ndarray,
           after: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(turn (n,) radians, incoming (n, 2), outgoing (n, 2) unit chords) at arc lengths `s`
    between the chords from `before` and to `after`."""
    here = stroke.points_at(curve.t_at(s))
    incoming = here - stroke.points_at(curve.t_at(before))
    outgoing = stroke.points_at(curve.t_at(after)) - here
    a, b = np.linalg.norm(incoming, axis=1), np.linalg.norm(outgoing, axis=1)
    cos = np.einsum("ij,ij->i", incoming, outgoing) / np.maximum(a * b, 1e-12)
    turn = np.where(a * b > 1e-12, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)
    return turn, incoming / np.maximum(a, 1e-12)[:, None], outgoing / np.maximum(b, 1e-12)[:, None]


def _directions(stroke: Stroke, curve: DenseCurve, s: np.ndarray, reach: np.ndarray, lo: float,
                hi: float) -> np.ndarray:
    """Unit directions at arc lengths `s`: the chord over +-reach, kept within [lo, hi] (a
    column does not look round its own corners): a fan on bends, the tangent at the
    stroke's own ends. Within a reach of a corner the chord stops at the corner but keeps
    its other side, so the end rows follow the column's last reach, not the corner's own
    rounding (over the last hundredth of a millimetre it turns towards the next piece: the
    inside of the last rows, held below that rounding's radius, shrank to nothing and left
    a slit)."""
    w = reach
    if lo <= 0.0:
        w = np.minimum(w, s - lo)
    if hi >= curve.length:
        w = np.minimum(w, hi - s)
    chord = stroke.points_at(curve.t_at(np.minimum(s + w, hi))) - stroke.points_at(curve.t_at(np.maximum(s - w, lo)))
    norm = np.linalg.norm(chord, axis=1, keepdims=True)
    # At the ends the tangent is taken just inside the column: at a corner's own point it
    # would be the next piece's (the last rows would swing round beyond the corner).
    inside = np.clip(s, lo + min(END_INSIDE, (hi - lo) / 2), hi - min(END_INSIDE, (hi - lo) / 2))
    return np.where(norm > 1e-6, chord / np.maximum(norm, 1e-12), stroke.tangents_at(curve.t_at(inside)))


def column_rows(stroke: Stroke, curve: DenseCurve, half_at, lo: float, hi: float, spacing: float, *,
                before: float = 0.0, after: float = 0.0, cap: bool = False) -> Rows:
    """Rows of the column covering arc lengths [lo, hi] mm of `stroke`, running on straight
    `before` mm ahead of lo and `after` mm past hi (along the end directions; `cap`: the
    rows ahead of lo narrow to a round cap).

    half_at: arc lengths (n,) -> half widths (n,) mm. Rows are spaced so that the longer
    rail has one every `spacing` / 2 (module doc), an odd number of gaps when there is room
    (the zigzag ends on the other rail), the first and last exactly at the ends.
    """
    step = spacing / 2.0
    inner = curve.s[(curve.s > lo) & (curve.s < hi)]
    count = max(2, int(np.ceil((hi - lo) / (step / FINE))) + 1)
    fine = np.union1d(np.linspace(lo, hi, count), inner)
    half = half_at(fine)
    direction = _directions(stroke, curve, fine, half, lo, hi)
    normal = np.column_stack([-direction[:, 1], direction[:, 0]])
    theta = np.unwrap(np.arctan2(direction[:, 1], direction[:, 0]))
    kappa = np.gradient(theta, fine) if len(fine) > 2 else np.zeros(len(fine))
    room = MAX_INNER_REACH / np.maximum(np.abs(kappa), 1e-12)
    left = np.where(kappa > 0, np.minimum(half, room), half)
    right = np.where(kappa < 0, np.minimum(half, room), half)
    centre = stroke.points_at(curve.t_at(fine))
    rails = [centre + normal * left[:, None], centre - normal * right[:, None], centre]
    u = np.concatenate([[0.0], np.cumsum(np.max([np.linalg.norm(np.diff(r, axis=0), axis=1) for r in rails], axis=0))])
    gaps = max(1, int(round(u[-1] / step)))
    if gaps % 2 == 0 and u[-1] > step:
        gaps += 1
    at = np.interp(np.linspace(0.0, u[-1], gaps + 1), u, fine)
    rows = Rows(centre=stroke.points_at(curve.t_at(at)), normal=_interp_normals(at, fine, normal),
                left=np.interp(at, fine, left), right=np.interp(at, fine, right), t=curve.t_at(at), s=at)
    parts = [rows]
    if before > 1e-9:
        parts.insert(0, _run_on(rows.take([0]), -direction[0], before, step, ahead=False, round_cap=cap))
    if after > 1e-9:
        parts.append(_run_on(rows.take([-1]), direction[-1], after, step, ahead=True))
    return Rows.concat(parts) if len(parts) > 1 else rows


def _interp_normals(at: np.ndarray, fine: np.ndarray, normal: np.ndarray) -> np.ndarray:
    n = np.column_stack([np.interp(at, fine, normal[:, 0]), np.interp(at, fine, normal[:, 1])])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def _run_on(end: Rows, outward: np.ndarray, distance: float, step: float, *, ahead: bool,
            round_cap: bool = False) -> Rows:
    """Rows continuing a column straight on from its end row `end` (one row) along
    `outward` for `distance` mm, about every `step` mm, in sewing order: moving away past the
    column's last row (`ahead`), or coming in towards its first row. `round_cap`: the rows
    narrow as a half disc of radius `distance` does (a round pen's corner)."""
    count = max(1, int(np.ceil(distance / step - 1e-9)))
    offsets = np.arange(1, count + 1) * (distance / count)
    if round_cap:
        offsets = offsets[offsets < distance - 1e-9]  # the last would have no width
    order = offsets if ahead else offsets[::-1]
    n = len(order)
    share = np.sqrt(np.maximum(1.0 - (order / distance) ** 2, 0.0)) if round_cap else np.ones(n)
    return Rows(centre=end.centre[0] + outward * order[:, None], normal=np.repeat(end.normal, n, axis=0),
                left=end.left[0] * share, right=end.right[0] * share, t=np.repeat(end.t, n),
                s=np.repeat(end.s, n))


def mitre_reach(turn: float, mitre_limit: float) -> float | None:
    """How far (in half widths) a mitred corner's rows run on past the corner point:
    tan(turn / 2); None when the mitre's outer point lies beyond `mitre_limit` half widths
    of the corner point (1 / cos(turn / 2)): such a corner is split instead."""
    if 1.0 / max(np.cos(turn / 2.0), 1e-12) > mitre_limit:
        return None
    return float(np.tan(turn / 2.0))


def _cover_area(rows: Rows):
    """The area a column's rows cover: the union of the quadrilaterals between consecutive
    rows (a column that folds over itself stays one area; rows far apart are not joined)."""
    if len(rows) < 2:
        return shapely.Polygon()
    lp, rp = rows.left_points, rows.right_points
    quads = np.stack([lp[:-1], lp[1:], rp[1:], rp[:-1]], axis=1)
    apart = np.linalg.norm(rows.centre[1:] - rows.centre[:-1], axis=1)
    quads = quads[apart <= 2.0 * (rows.left[:-1] + rows.right[:-1]) + 1e-9]
    if not len(quads):
        return shapely.Polygon()
    return shapely.union_all(shapely.make_valid(shapely.polygons(quads)))


def cut_rows(rows: Rows, cover, overlap: float) -> Rows:
    """`rows` with what lies under `cover` (a shapely area sewn on top later) taken away, each
    cut end running `overlap` mm on under it (no slit between the two): a row with less than
    MIN_PIECE mm left outside it is dropped; otherwise its longest piece outside is kept."""
    if cover.is_empty or not len(rows):
        return rows
    lp, rp = rows.left_points, rows.right_points
    lines = shapely.linestrings(np.stack([rp, lp], axis=1))
    hit = np.flatnonzero(shapely.intersects(lines, cover))
    if not len(hit):
        return rows
    keep = np.ones(len(rows), dtype=bool)
    cut, mids, lefts, rights = [], [], [], []
    for i, free in zip(hit.tolist(), shapely.difference(lines[hit], cover)):
        parts = [g for g in getattr(free, "geoms", [free]) if not g.is_empty]
        piece = max(parts, key=lambda g: g.length) if parts else None
        if piece is None or piece.length < MIN_PIECE:
            keep[i] = False
            continue
        a, b = np.asarray(piece.coords)[[0, -1]]
        # Offsets of the piece's ends along the row's normal, from its centre; a cut end runs
        # on under the cover (within the row).
        n = rows.normal[i]
        lo, hi = sorted((float(np.dot(a - rows.centre[i], n)), float(np.dot(b - rows.centre[i], n))))
        if lo > -rows.right[i] + 1e-6:
            lo = max(-rows.right[i], lo - overlap)
        if hi < rows.left[i] - 1e-6:
            hi = min(rows.left[i], hi + overlap)
        mid = 0.5 * (lo + hi)
        cut.append(i)
        mids.append(mid)
        lefts.append(hi - mid)
        rights.append(mid - lo)
    if cut:
        rows = rows.recentred(np.array(cut), np.array(mids), np.array(lefts), np.array(rights))
    return rows.take(np.flatnonzero(keep))


def _joined(corners: list[Corner], half_at) -> tuple[list[Corner], list[tuple[float, float]]]:
    """Corners closer along the stroke than their half width, as one corner each (a line
    that jogs sideways by less than its width where a spike leaves it: the jog gets no
    column of its own); and the (start, end) arc lengths of the jogs."""
    joined: list[Corner] = []
    jogs: list[tuple[float, float]] = []
    for corner in corners:
        last = joined[-1] if joined else None
        if last is not None and corner.s - last.s < float(half_at(np.array([corner.s]))[0]):
            turn = float(np.arccos(np.clip(np.dot(last.incoming, corner.outgoing), -1.0, 1.0)))
            cross = last.incoming[0] * corner.outgoing[1] - last.incoming[1] * corner.outgoing[0]
            start = jogs.pop()[0] if jogs and jogs[-1][1] == last.s else last.s
            joined[-1] = Corner(last.s, 0.5 * (last.point + corner.point), last.incoming, corner.outgoing, turn,
                                bool(cross > 0))
            jogs.append((start, corner.s))
        else:
            joined.append(corner)
    return joined, jogs


def stroke_columns(stroke: Stroke, curve: DenseCurve, half_at, spacing: float, *, corner_angle: float,
                   mitre_limit: float, overlap: float) -> list[Column]:
    """The columns of `stroke` (module doc): half_at maps arc lengths to half widths mm."""
    corners, jogs = _joined(find_corners(stroke, curve, half_at(curve.s), corner_angle), half_at)
    # A corner joined from several ends where its jog does: the column after starts there.
    resume = {start: end for start, end in jogs}
    cuts = [0.0] + [c.s for c in corners] + [curve.length]
    starts = [0.0] + [resume.get(c.s, c.s) for c in corners]
    runs = [[0.0, 0.0] for _ in range(len(cuts) - 1)]  # run-on distances before and after each column
    mitres: dict[int, Corner] = {}
    for k, corner in enumerate(corners):
        h = float(half_at(np.array([corner.s]))[0])
        reach = mitre_reach(corner.turn, mitre_limit)
        if reach is not None:
            runs[k][1] = reach * h + overlap
            runs[k + 1][0] = reach * h
            mitres[k] = corner
        else:
            runs[k + 1][0] = h  # a round cap over the corner's outside, sewn on top
    rows = [column_rows(stroke, curve, half_at, starts[k], cuts[k + 1], spacing, before=runs[k][0],
                        after=runs[k][1], cap=k > 0 and k - 1 not in mitres)
            for k in range(len(cuts) - 1)]
    # Each side of a mitre stops at the mitre line (the one before runs on under the one
    # after by `overlap`); then the column before every corner is cut back under the one
    # after it, which is sewn on top of it.
    for k, corner in mitres.items():
        reach = 2.0 * (runs[k + 1][0] + 2.0 * float(half_at(np.array([corner.s]))[0]))  # rows the line can meet
        rows[k] = _cut_at_line(rows[k], corner, after=False, margin=overlap, within=reach)
        rows[k + 1] = _cut_at_line(rows[k + 1], corner, after=True, margin=0.0, within=reach)
    for k in range(len(corners)):
        near = _near(rows[k + 1], corners[k], rows[k])
        rows[k] = cut_rows(rows[k], _cover_area(near), overlap)
    # Corners close together (a line that kinks where a spike leaves it): any column near a
    # corner is cut back under every later column near it too.
    for k, corner in enumerate(corners):
        reach = CLUSTER * float(half_at(np.array([corner.s]))[0]) + overlap
        close = [j for j in range(len(rows))
                 if len(rows[j]) and np.min(np.linalg.norm(rows[j].centre - corner.point, axis=1)) <= reach]
        for i in close:
            later = [_within(rows[j], corner.point, reach) for j in close if j > i and not (j == i + 1 == k + 1)]
            later = [r for r in later if len(r) > 1]
            if later:
                rows[i] = cut_rows(rows[i], shapely.union_all([_cover_area(r) for r in later]), overlap)
    _thin_crowded(rows, spacing)
    columns = []
    for k, r in enumerate(rows):
        if starts[k] > cuts[k]:  # the jog before this column: walked along its centre
            columns.append(Column(r.take(np.zeros(0, dtype=int)), cuts[k], starts[k]))
        columns.append(Column(r, starts[k], cuts[k + 1]))
    return columns


def _thin_crowded(rows: list[Rows], spacing: float) -> None:
    """In place: rows whose rail points crowd (more than CROWDED needle points of other rows
    within DENSITY_RADIUS mm: the inside of a tight bend, the ground where corners meet) are
    left out, in sewing order, while they still crowd, and only where the rows kept either
    side of one lie within THIN_GAP x `spacing` mm of each other on both rails (the outside
    of the bend stays covered: no slit there). Whole rows go, so the sides still alternate; only
    the rows whose points crowd at first are visited."""
    sizes = [len(r) for r in rows]
    if sum(sizes) < 2:
        return
    ends = np.concatenate([np.concatenate([r.left_points, r.right_points]) for r in rows if len(r)])
    row_of = np.concatenate([np.tile(np.arange(n), 2) + base for n, base in
                             zip([n for n in sizes if n], np.cumsum([0] + [n for n in sizes if n])[:-1])])
    tree = cKDTree(ends)
    pairs = tree.query_pairs(DENSITY_RADIUS, output_type="ndarray")
    pairs = pairs[row_of[pairs[:, 0]] != row_of[pairs[:, 1]]].astype(np.int32)
    # Each point's neighbours of other rows, both ways (a sparse graph: millions of pairs on
    # the densest columns, kept as int32), and how many of them belong to rows still kept
    # (updated as rows go): a suspect's check is a look-up (it used to search the tree per
    # point, and each row's points among all of them).
    graph = coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(len(ends),) * 2)
    del pairs
    graph = (graph + graph.T).tocsr()
    first, near = graph.indptr, graph.indices
    # Each row has both ends but sews one (the sides alternate): two ends per needle point.
    count = np.diff(first)
    if count.max(initial=0) <= 2 * CROWDED:
        return
    suspects = np.unique(row_of[count > 2 * CROWDED]).tolist()
    kept_near = count.copy()
    points_of = np.argsort(row_of, kind="stable").reshape(-1, 2).tolist()  # each row's left, right point
    alive = [True] * (int(row_of.max()) + 1)
    column_of = np.repeat(np.arange(len(sizes)), sizes).tolist()
    rails = ends.tolist()
    for row in suspects:
        left, right = points_of[row]
        # A row narrower than the density circle lies in it whole: there only the spacing
        # itself bounds the gap.
        dx, dy = rails[left][0] - rails[right][0], rails[left][1] - rails[right][1]
        narrow = math.sqrt(dx * dx + dy * dy) < 2.0 * DENSITY_RADIUS
        if (kept_near[left] > 2 * CROWDED or kept_near[right] > 2 * CROWDED) and \
                _gap_closed(rails, points_of, column_of, alive, row, (1.0 if narrow else THIN_GAP) * spacing):
            alive[row] = False
            for point in (left, right):
                kept_near[near[first[point]:first[point + 1]]] -= 1
    alive = np.array(alive, dtype=bool)
    base = 0
    for j, n in enumerate(sizes):
        if n:
            keep = np.flatnonzero(alive[base:base + n])
            if len(keep) < n:
                rows[j] = rows[j].take(keep)
            base += n


def _gap_closed(ends: list, points_of: list, column_of: list, alive: list, row: int, spacing: float) -> bool:
    """Whether the rows kept (`alive`) before and after `row` in its column lie within
    `spacing` mm of each other on both rails (`ends`: the rail points, `points_of` each row's
    left and right one; Python lists: one row at a time)."""
    before, after = row - 1, row + 1
    while before >= 0 and column_of[before] == column_of[row] and not alive[before]:
        before -= 1
    while after < len(alive) and column_of[after] == column_of[row] and not alive[after]:
        after += 1
    if before < 0 or after >= len(alive) or column_of[before] != column_of[row] or column_of[after] != column_of[row]:
        return False  # a column's first and last rows stay
    # the same operations as numpy's norm of the differences: sqrt(dx * dx + dy * dy)
    far = 0.0
    for a, b in zip(points_of[before], points_of[after]):
        dx, dy = ends[a][0] - ends[b][0], ends[a][1] - ends[b][1]
        far = max(far, math.sqrt(dx * dx + dy * dy))
    return far <= spacing + 1e-9


def _within(rows: Rows, point: np.ndarray, reach: float) -> Rows:
    """The rows whose centre lies within `reach` mm of `point`."""
    return rows.take(np.flatnonzero(np.linalg.norm(rows.centre - point, axis=1) <= reach))


def _cut_at_line(rows: Rows, corner: Corner, *, after: bool, margin: float, within: float) -> Rows:
    """Rows on one side of a mitred corner's line (through the corner point halfway between
    the way in, backwards, and the way out): the side of the column after it (`after`) or
    before it, each row running `margin` mm past the line. Only rows within `within` mm of
    the corner along the stroke are cut (the line goes on beyond the column's end)."""
    bisector = corner.outgoing - corner.incoming
    norm = np.linalg.norm(bisector)
    if norm < 1e-9:
        return rows
    b = bisector / norm
    m = np.array([b[1], -b[0]])
    if np.dot(m, corner.outgoing) < 0:
        m = -m  # m points into the column after
    if not after:
        m = -m
    lp, rp = rows.left_points, rows.right_points
    fl, fr = (lp - corner.point) @ m + margin, (rp - corner.point) @ m + margin
    near = np.abs(rows.s - corner.s) <= within
    fl, fr = np.where(near, fl, 1.0), np.where(near, fr, 1.0)
    keep = (fl > 1e-9) | (fr > 1e-9)
    cut = np.flatnonzero(keep & ((fl < 0) | (fr < 0)))
    mids, lefts, rights = [], [], []
    for i in cut.tolist():
        # the row from its right point (offset -right) to its left (+left), cut where f = 0
        a, b_ = -rows.right[i], rows.left[i]
        x = a + (b_ - a) * (0.0 - fr[i]) / (fl[i] - fr[i])
        lo, hi = (x, b_) if fr[i] < 0 else (a, x)
        mid = 0.5 * (lo + hi)
        mids.append(mid)
        lefts.append(hi - mid)
        rights.append(mid - lo)
    if len(cut):
        rows = rows.recentred(cut, np.array(mids), np.array(lefts), np.array(rights))
    return rows.take(np.flatnonzero(keep))


def _near(rows: Rows, corner: Corner, other: Rows) -> Rows:
    """The rows of `rows` (the column after `corner`) near enough to it to lie over `other`
    (the column before): where the two centre lines, parting at the corner's inside angle,
    are still less than both half widths apart, and two widths more."""
    if not len(rows) or not len(other):
        return rows
    widths = rows.left.max() + rows.right.max() + other.left.max() + other.right.max()
    inside = np.pi - corner.turn
    reach = 0.5 * widths / max(np.sin(min(inside, np.pi / 2)), 0.05) + widths
    close = np.linalg.norm(rows.centre - corner.point, axis=1) <= reach
    return rows.take(np.flatnonzero(close))
