"""G2/G3 arcs fitted to a dense polyline within a tolerance, to cut the G-code line count.

Greedy and deterministic: from each vertex take the longest run of following vertices that
one straight line or one circular arc passes within `tolerance` of, found by exponential
search (from the previous run's length) then binary search on the run length. Arc centres are rounded the way they will be written
(I, J to 0.001 mm from the start point) before the fit is checked, so the check holds for
the arc GRBL will actually cut.
"""

from __future__ import annotations

import numpy as np

LINE, CW, CCW = 1, 2, 3
# Arcs flatter than this are written as lines: the line already fits, and huge I/J words
# would waste characters and GRBL's arc radius check precision.
MAX_RADIUS = 2000.0
# Stay clear of full circles: GRBL reads an arc whose end meets its start as a full turn.
MAX_SWEEP = 1.5 * np.pi
# GRBL rejects arcs whose start and end radii differ by more than 0.005 mm (error:33).
_RADIUS_MISMATCH = 0.002


def _line_fits(p: np.ndarray, tolerance: float) -> bool:
    a = p[0]
    dx, dy = p[-1, 0] - a[0], p[-1, 1] - a[1]
    length2 = dx * dx + dy * dy
    if length2 == 0.0:
        return False
    rx, ry = p[:, 0] - a[0], p[:, 1] - a[1]
    t = np.clip((rx * dx + ry * dy) / length2, 0.0, 1.0)
    ex, ey = rx - t * dx, ry - t * dy
    return bool((ex * ex + ey * ey).max() <= tolerance * tolerance)


def _leaves_box(centre, radius, start_angle, sweep, box) -> bool:
    """True when the arc sticks out of box (xmin, ymin, xmax, ymax). Its end points lie
    inside, so it can only leave at one of its axis-extreme points within the sweep."""
    if box is None:
        return False
    lo, hi = (start_angle, start_angle + sweep) if sweep > 0 else (start_angle + sweep, start_angle)
    for k, (dx, dy) in enumerate(((1, 0), (0, 1), (-1, 0), (0, -1))):
        angle = k * np.pi / 2
        # is this axis direction inside the swept interval (mod 2 pi)?
        turns = np.ceil((lo - angle) / (2 * np.pi))
        if angle + turns * 2 * np.pi <= hi:
            x, y = centre[0] + dx * radius, centre[1] + dy * radius
            if x < box[0] or y < box[1] or x > box[2] or y > box[3]:
                return True
    return False


def _arc_fits(p: np.ndarray, tolerance: float, quantum: float, box=None) -> tuple[np.ndarray, int] | None:
    """Centre (2,) and direction (CW/CCW) of an arc through p[0], p[-1] within tolerance."""
    a, m, b = p[0], p[len(p) // 2], p[-1]
    ab, am = b - a, m - a
    cross = ab[0] * am[1] - ab[1] * am[0]
    if abs(cross) < 1e-12:
        return None
    # circumcentre of a, m, b
    bb, mm = ab @ ab, am @ am
    ux = (am[1] * bb - ab[1] * mm) / (2 * cross)
    uy = (ab[0] * mm - am[0] * bb) / (2 * cross)
    offset = np.round(np.array([ux, uy]) / quantum) * quantum
    centre = a + offset
    radius = float(np.hypot(*offset))
    if radius > MAX_RADIUS or radius == 0.0:
        return None
    if abs(float(np.hypot(*(b - centre))) - radius) > _RADIUS_MISMATCH:
        return None
    rx, ry = p[:, 0] - centre[0], p[:, 1] - centre[1]
    err = np.abs(np.sqrt(rx * rx + ry * ry) - radius).max()
    if err > tolerance:
        return None
    direction = CCW if cross < 0 else CW
    # the points must advance around the centre one way: every step turns with the arc
    turn = np.arctan2(rx[:-1] * ry[1:] - ry[:-1] * rx[1:], rx[:-1] * rx[1:] + ry[:-1] * ry[1:])
    if direction == CW:
        turn = -turn
    sweep = float(turn.sum())
    if turn.min() <= 0 or sweep > MAX_SWEEP:
        return None
    # chords between consecutive points may cut inside the circle: bound their sagitta
    cx, cy = np.diff(p[:, 0]), np.diff(p[:, 1])
    if (cx * cx + cy * cy).max() / (8 * radius) + err > tolerance:
        return None
    # reversed (later passes), the arc is written from its other end: allow for that radius
    start_angle = float(np.arctan2(ry[0], rx[0]))
    if _leaves_box(centre, radius + _RADIUS_MISMATCH, start_angle, sweep if direction == CCW else -sweep, box):
        return None
    return centre, direction


def _hopeless_triples(p: np.ndarray, tolerance: float) -> np.ndarray:
    """(N,) True where vertices i, i+1, i+2 fit neither a line nor an arc within tolerance.

    A necessary condition, vectorized: a run from i that cannot take in i+2 cannot take
    in anything longer, so the greedy loop writes one line there without fitting.
    """
    out = np.zeros(len(p), dtype=bool)
    if len(p) < 3:
        return out
    a, m, b = p[:-2], p[1:-1], p[2:]
    ab, am = b - a, m - a
    cross = ab[:, 0] * am[:, 1] - ab[:, 1] * am[:, 0]
    chord = np.hypot(*ab.T)
    with np.errstate(divide="ignore", invalid="ignore"):
        line_err = np.abs(cross) / chord  # distance of m from the line a-b
        # circumradius R = |ab| |am| |mb| / (2 |cross|)
        radius = chord * np.hypot(*am.T) * np.hypot(*(b - m).T) / (2 * np.abs(cross))
        longest = np.maximum(np.hypot(*am.T), np.hypot(*(b - m).T))
        sag = longest * longest / (8 * radius)
    # the projection of m must also fall between a and b for the line to pass near it
    t = (am * ab).sum(axis=1) / np.where(chord > 0, chord * chord, 1.0)
    line_ok = (line_err <= tolerance) & (t >= 0) & (t <= 1)
    arc_ok = np.isfinite(radius) & (radius <= MAX_RADIUS) & (sag <= tolerance)
    out[:-2] = ~(line_ok | arc_ok) & (chord > 0)
    return out


def fit_arcs(points: np.ndarray, tolerance: float, *, quantum: float = 0.001, box=None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lines and arcs through a subset of `points` that pass within `tolerance` of all.

    points: (N, 2) dense polyline, mm, machine frame (+y up, so G2 = clockwise).
    Returns vertices (M, 2) (a subset of points, first and last kept), kinds (M-1,) int8
    (1 line, 2 clockwise arc, 3 counter-clockwise arc) and centres (M-1, 2) (NaN for lines).
    box: (xmin, ymin, xmax, ymax) that no arc may bulge out of (the bed), or None.
    """
    p = np.asarray(points, dtype=float)
    n = len(p)
    hopeless = _hopeless_triples(p, tolerance)
    keep = [0]
    kinds: list[int] = []
    centres: list[tuple[float, float]] = []

    def fit(i: int, j: int):
        if j - i == 1:
            return LINE, None
        run = p[i:j + 1]
        if _line_fits(run, tolerance):
            return LINE, None
        arc = _arc_fits(run, tolerance, quantum, box)
        if arc is None:
            return None
        return arc[1], arc[0]

    i = 0
    guess = 2
    while i < n - 1:
        if i + 2 <= n - 1 and hopeless[i]:
            # nothing longer than one segment can start here: write the line at once
            keep.append(i + 1)
            kinds.append(LINE)
            centres.append((np.nan, np.nan))
            i += 1
            continue
        good_j, good = i + 1, fit(i, i + 1)
        # runs along a smooth curve have similar lengths: search from the last one's
        step = max(2, guess)
        bad_j = None
        while True:
            j = min(i + step, n - 1)
            result = fit(i, j) if j > good_j else None
            if result is None:
                bad_j = j if j > good_j else None
                break
            good_j, good = j, result
            if j == n - 1:
                break
            step *= 2
        if bad_j is not None:
            lo, hi = good_j, bad_j
            while hi - lo > 1:
                mid = (lo + hi) // 2
                result = fit(i, mid)
                if result is None:
                    hi = mid
                else:
                    lo, good = mid, result
            good_j = lo
        guess = good_j - i
        kind, centre = good
        keep.append(good_j)
        kinds.append(kind)
        centres.append((np.nan, np.nan) if centre is None else (float(centre[0]), float(centre[1])))
        i = good_j
    return p[keep], np.array(kinds, dtype=np.int8), np.array(centres, dtype=float).reshape(-1, 2)
