"""Running stitch: needle points along the curve, within a chord tolerance, on every corner.

Ink/Stitch's rules: target stitch length (2.5 mm), no stitch chord leaves a band of
`tolerance` (0.2 mm) around the curve (tight curves get shorter stitches, never looser
ones), a needle point on every turn sharper than `corner_angle`, and equal stitches
within each piece between corners.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.needles import BODY, GRID, LONGEST_STITCH, SNAP_ALLOWANCE, NeedlePoints
from fabrication.embroidery.sampling import DenseCurve, dense_curve
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import Stroke

# The stitch a walk aims at, from one step of the files' grid to the longest stitch stored.
STITCH_LENGTH = Range(GRID, LONGEST_STITCH, unit="mm", name="--stitch-length")
# Largest chord-to-curve distance: under one grid step the files cannot follow it.
TOLERANCE = Range(GRID, 5.0, unit="mm", name="--tolerance")
CORNER_ANGLE = Range(0.0, 180.0, unit="degrees", name="corner angle", low_open=True, high_open=True)

# Dense sampling tolerance (mm): small against every stitch tolerance we accept. The curve
# strays at most this far from the dense polyline on which chord errors are measured, so
# it comes off the tolerance budget, like the snap to the 0.1 mm grid.
DENSE_TOLERANCE = 0.01
TOLERANCE_RESERVE = SNAP_ALLOWANCE + DENSE_TOLERANCE


@dataclass(frozen=True, kw_only=True)
class RunningOptions:
    """stitch_length: target stitch in mm; tolerance: largest chord-to-curve distance in mm;
    corner_angle: turns sharper than this (degrees) always get a needle point."""

    stitch_length: float = ranged(2.5, STITCH_LENGTH)
    tolerance: float = ranged(0.2, TOLERANCE)
    corner_angle: float = ranged(45.0, CORNER_ANGLE)

    def __post_init__(self) -> None:
        check_ranges(self)


def chord_deviation(curve: DenseCurve, s_stitch: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Largest distance (mm) from the curve to each stitch chord: (n - 1,) for n needle
    points at arc lengths `s_stitch` (increasing) with positions `points` (n, 2)."""
    n = len(s_stitch)
    dev = np.zeros(max(n - 1, 0))
    if n < 2:
        return dev
    k = np.clip(np.searchsorted(s_stitch, curve.s, side="right") - 1, 0, n - 2)
    a, b = points[k], points[k + 1]
    ab = b - a
    ap = curve.points - a
    denom = np.einsum("ij,ij->i", ab, ab)
    u = np.clip(np.divide(np.einsum("ij,ij->i", ap, ab), denom, out=np.zeros(len(k)), where=denom > 0), 0, 1)
    d = np.linalg.norm(ap - u[:, None] * ab, axis=1)
    # k is sorted (the curve runs forward): reduce each stitch's run of dense points.
    starts = np.concatenate([[0], np.flatnonzero(np.diff(k)) + 1])
    dev[k[starts]] = np.maximum.reduceat(d, starts)
    return dev


def stitch_lengths_along(curve: DenseCurve, options: RunningOptions, *,
                         breaks: np.ndarray | None = None) -> np.ndarray:
    """Arc lengths (n,) of the needle points of a running stitch on `curve`, start and end
    included. `breaks` (arc lengths) are extra points every stitch must meet, like corners."""
    s = curve.s
    tol = options.tolerance - TOLERANCE_RESERVE
    corner = np.abs(curve.turns) > np.radians(options.corner_angle)
    kappa = np.abs(curve.curvature)
    kappa[corner] = 0.0  # a corner is a kink, not a tight curve: it gets its own point
    # A chord c on radius R strays c^2 / (8 R) from the arc: the longest allowed chord.
    allowed = np.minimum(options.stitch_length, np.sqrt(8.0 * tol / np.maximum(kappa, 1e-12)))
    per_piece = np.minimum(allowed[:-1], allowed[1:])
    # u counts stitches: equal steps in u are equal stitches where the curvature is even.
    u = np.concatenate([[0.0], np.cumsum(np.diff(s) / per_piece)])
    cuts = [[0.0, curve.length], s[corner]]
    if breaks is not None and len(breaks):
        cuts.append(np.clip(np.asarray(breaks, dtype=float), 0.0, curve.length))
    cut_s = np.unique(np.concatenate(cuts))
    cut_u = np.interp(cut_s, s, u)
    du = np.diff(cut_u)
    n = np.maximum(1, np.ceil(du - 1e-9)).astype(int)
    piece = np.repeat(np.arange(len(n)), n)
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    s_out = np.interp(cut_u[piece] + du[piece] * k / n[piece], u, s)
    s_out[k == 0] = cut_s[:-1]  # exact corners and breaks, not a round trip through u
    return np.append(s_out, curve.length)


def refine_to_tolerance(stroke: Stroke, curve: DenseCurve, s_points: np.ndarray,
                        tolerance: float, *, rounds: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Split every stitch whose chord strays more than `tolerance` from the curve (measured).
    Returns (s (n,), t (n,))."""
    for _ in range(rounds):
        t = curve.t_at(s_points)
        dev = chord_deviation(curve, s_points, stroke.points_at(t))
        bad = dev > tolerance
        if not bad.any():
            return s_points, t
        s_points = np.sort(np.concatenate([s_points, 0.5 * (s_points[:-1][bad] + s_points[1:][bad])]))
    return s_points, curve.t_at(s_points)


# A hole this close (mm) to one of the last few needle points is the same hole (0.2 mm,
# plus the files' 0.1 mm grid): where a line retraces itself (a spike drawn out and back)
# equal stitches on the way back would pierce the holes of the way out.
FRESH_HOLE = 0.35
RECENT_HOLES = 4


def _fresh_holes(stroke: Stroke, curve: DenseCurve, s: np.ndarray, fixed: np.ndarray,
                 gap: float = FRESH_HOLE) -> np.ndarray:
    """Arc lengths `s` (n,) with each needle point that would land within `gap` mm of one
    of the RECENT_HOLES before it (its own predecessor aside) moved `gap` along the curve,
    forward or back, where that clears them; `fixed` (n,) points (corners, ends) stay."""
    pts = stroke.points_at(curve.t_at(s))
    near = np.zeros(len(s), dtype=bool)
    for lag in range(2, RECENT_HOLES + 1):
        near[lag:] |= np.linalg.norm(pts[lag:] - pts[:-lag], axis=1) < gap
    s = s.copy()
    for i in np.flatnonzero(near & ~fixed).tolist():  # few: only retraced places
        recent = pts[max(0, i - RECENT_HOLES):i - 1]
        for shift in (gap, -gap):
            moved = s[i] + shift
            if not s[i - 1] + GRID < moved < s[i + 1] - GRID:
                continue
            point = stroke.points_at(curve.t_at(np.array([moved])))[0]
            if np.linalg.norm(recent - point, axis=1).min() >= gap:
                s[i], pts[i] = moved, point
                break
    return s


def running_stitch(stroke: Stroke, options: RunningOptions = RunningOptions(), *,
                   curve: DenseCurve | None = None, breaks: np.ndarray | None = None,
                   fresh: float = FRESH_HOLE) -> NeedlePoints:
    """Running stitch along `stroke` (mm). Returns needle points, start and end included.
    fresh: how far (mm) a needle point keeps from the last few where the line retraces
    itself (more for the base of a triple stitch, whose passes pierce beside each hole)."""
    curve = curve if curve is not None else dense_curve(stroke, DENSE_TOLERANCE)
    s = stitch_lengths_along(curve, options, breaks=breaks)
    s, t = refine_to_tolerance(stroke, curve, s, options.tolerance - TOLERANCE_RESERVE)
    corners = curve.s[np.abs(curve.turns) > np.radians(options.corner_angle)]
    fixed = np.isin(s, corners)
    fixed[[0, -1]] = True
    if breaks is not None and len(breaks):
        fixed |= np.isin(s, breaks)
    moved = _fresh_holes(stroke, curve, s, fixed, fresh)
    if not np.array_equal(moved, s):
        s, t = refine_to_tolerance(stroke, curve, moved, options.tolerance - TOLERANCE_RESERVE)
    return NeedlePoints.of(stroke.points_at(t), t, BODY)
