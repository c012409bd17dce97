"""What a column of satin or zigzag looks like sewn, measured on a stitch plan: how wide it
is along its stroke, and where its stitches leave the fabric bare between them (slits).

- Sewn width: along each stroke, every `step` mm, the top (BODY) needle points within one
  `window` mm of that place along the curve (their nearest point on it) give the column's
  extent either side; the width is the widest reach left plus the widest right.
- Slits: points of the column's band (within the expected half width less `margin` and the
  short stitches' inset, every 0.1 mm along, 9 across) farther than half the spacing plus `slack` from every top stitch
  of the stroke: there adjacent stitches are more than the spacing apart (the thread
  covers up to half the spacing either side of a stitch in a sound column). Grouped into
  places 1 mm apart.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import cKDTree

from fabrication.embroidery.needles import BODY, TACK, TRAVEL
from fabrication.embroidery.plan import STITCH
from fabrication.embroidery.running import DENSE_TOLERANCE
from fabrication.embroidery.sampling import dense_curve


RETRACE = 0.3  # mm: two passes of a stroke this close are one line drawn twice


def _top(plan, k: int) -> np.ndarray:
    """Rows of the top stitches of sewn stroke `k` (needle down, role BODY)."""
    return np.flatnonzero((plan.strokes == k) & (plan.kinds == STITCH) & (plan.roles == BODY))


def _frame(stroke):
    """(dense curve, its shapely line, unit tangents per dense point)."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)
    tangent = np.gradient(curve.points, axis=0)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-12)
    return curve, shapely.LineString(curve.points), tangent


def _along_and_across(curve, line, tangent, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Arc length of each point's nearest place on the curve, and its signed distance
    (left of the direction of travel positive)."""
    s = shapely.line_locate_point(line, shapely.points(points))
    foot = np.column_stack([np.interp(s, curve.s, curve.points[:, 0]), np.interp(s, curve.s, curve.points[:, 1])])
    tx, ty = np.interp(s, curve.s, tangent[:, 0]), np.interp(s, curve.s, tangent[:, 1])
    d = points - foot
    return s, np.sign(tx * d[:, 1] - ty * d[:, 0]) * np.hypot(d[:, 0], d[:, 1])


def sewn_widths(plan, k: int, *, step: float = 0.25, window: float = 0.4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s (M,) mm along sewn stroke k, points (M, 2) there, width (M,) mm sewn; NaN where
    one side has no needle point within the window)."""
    stroke = plan.sewn.strokes[k]
    curve, line, tangent = _frame(stroke)
    rows = _top(plan, k)
    s_p, off = _along_and_across(curve, line, tangent, plan.points[rows])
    s = np.arange(0.0, curve.length + 1e-9, step)
    order = np.argsort(s_p)
    s_p, off = s_p[order], off[order]
    lo = np.searchsorted(s_p, s - window)
    hi = np.searchsorted(s_p, s + window)
    width = np.full(len(s), np.nan)
    for j, (a, b) in enumerate(zip(lo, hi)):
        if b - a < 2:
            continue
        o = off[a:b]
        if o.max() > 0 and o.min() < 0:
            width[j] = o.max() - o.min()
    where = np.column_stack([np.interp(s, curve.s, curve.points[:, 0]), np.interp(s, curve.s, curve.points[:, 1])])
    # A stretch drawn twice is sewn once: its first pass measures where the second lies.
    tree = cKDTree(where)
    missing = np.flatnonzero(np.isnan(width))
    for j, others in zip(missing, tree.query_ball_point(where[missing], RETRACE)):
        found = [o for o in others if abs(s[o] - s[j]) > 4 * window and np.isfinite(width[o])]
        if found:
            width[j] = width[min(found, key=lambda o: np.hypot(*(where[o] - where[j])))]
    return s, where, width


def shared_ground(s: np.ndarray, where: np.ndarray, half: np.ndarray) -> np.ndarray:
    """(M,) True where another pass of the stroke (beyond `RETRACE` mm: not the same line
    drawn twice) comes within both half widths of a sample: a V's two sides or a crossing,
    whose inks merge, so one pass's width cannot be seen there. s, where, half: the samples'
    arc lengths, points and half widths (mm)."""
    tree = cKDTree(where)
    shared = np.zeros(len(s), dtype=bool)
    reach = 2.0 * float(half.max())
    for j, others in enumerate(tree.query_ball_point(where, reach)):
        for o in others:
            d = float(np.hypot(*(where[o] - where[j])))
            if RETRACE < d < half[j] + half[o] and abs(s[o] - s[j]) > 2.0 * (half[j] + half[o]) + d:
                shared[j] = True
                break
    return shared


def slits(plan, k: int, half_at, spacing: float, *, margin: float = 0.15, slack: float = 0.1,
          inset: float = 0.0, corners: np.ndarray | None = None) -> list[np.ndarray]:
    """Places (mm) where the top stitches of sewn stroke `k` leave a gap wider than
    `spacing` (module doc). half_at: arc lengths (n,) -> the expected needle half width (n,);
    inset: a share of the half width next to each rail not probed (where short stitches
    end short of the rail by design)."""
    stroke = plan.sewn.strokes[k]
    curve, _, tangent = _frame(stroke)
    rows = _top(plan, k)
    # The first top point of a run is the last of the tack or travel before it (the planner
    # tags it so): the stitch from it across the column is a top stitch.
    first = rows[np.concatenate([[True], np.diff(rows) > 1])] - 1
    first = first[(first >= 0) & (plan.kinds[np.maximum(first, 0)] == STITCH) & (plan.strokes[np.maximum(first, 0)] == k)
                  & np.isin(plan.roles[np.maximum(first, 0)], (TACK, TRAVEL))]
    rows = np.union1d(rows, first)
    if len(rows) < 2:
        return []
    # dense samples of the stitches actually sewn between consecutive top needle points
    consecutive = np.flatnonzero(np.diff(rows) == 1)
    a, b = plan.points[rows[consecutive]], plan.points[rows[consecutive] + 1]
    n = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / 0.05)).astype(int)
    owner = np.repeat(np.arange(len(n)), n + 1)
    frac = (np.arange(owner.size) - np.repeat(np.cumsum(n + 1) - (n + 1), n + 1)) / np.repeat(n, n + 1)
    thread = a[owner] + (b - a)[owner] * frac[:, None]
    s = np.arange(0.0, curve.length + 1e-9, 0.1)
    centre = np.column_stack([np.interp(s, curve.s, curve.points[:, 0]), np.interp(s, curve.s, curve.points[:, 1])])
    tx, ty = np.interp(s, curve.s, tangent[:, 0]), np.interp(s, curve.s, tangent[:, 1])
    normal = np.column_stack([-ty, tx]) / np.maximum(np.hypot(tx, ty), 1e-12)[:, None]
    half = np.maximum(half_at(s) * (1.0 - inset) - margin, 0.0)
    across = np.linspace(-1.0, 1.0, 9)
    probes = (centre[:, None, :] + normal[:, None, :] * (half[:, None] * across[None, :])[..., None]).reshape(-1, 2)
    if corners is not None and len(corners):
        # a corner's own band is its columns' (mitre, run-on): judged by the columns either side
        far = cKDTree(np.asarray(corners)).query(probes)[0] > 2.0 * float(half.max()) + margin
        probes = probes[far]
    distance, _ = cKDTree(thread).query(probes)
    bare = probes[distance > spacing / 2.0 + slack]
    return _places(bare)


def _places(points: np.ndarray, reach: float = 1.0) -> list[np.ndarray]:
    """One point per cluster of `points` (clusters: within `reach` mm of their first point)."""
    places: list[np.ndarray] = []
    taken = np.zeros(len(points), dtype=bool)
    if not len(points):
        return places
    tree = cKDTree(points)
    for i in range(len(points)):
        if taken[i]:
            continue
        places.append(points[i])
        taken[tree.query_ball_point(points[i], reach)] = True
    return places
