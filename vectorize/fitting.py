"""Curve fitting (paper 3.4): filter uncertain points, split at sharp features, fit cubic
B-splines with `scipy.interpolate.splprep`, and convert them to Bézier segments."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import splev, splprep

from vectorize.stroke import Stroke


@dataclass(frozen=True)
class TracedPoint:
    """A point of a traversed stroke with what the filter needs to know about it."""

    xy: np.ndarray
    keep: bool
    split: bool


def _dedupe(points: np.ndarray, min_step: float) -> np.ndarray:
    """Drop points closer than `min_step` to the previous kept one (splprep needs distinct points)."""
    if len(points) < 2:
        return points
    keep = [0]
    last = points[0]
    for i in range(1, len(points)):
        if np.linalg.norm(points[i] - last) >= min_step:
            keep.append(i)
            last = points[i]
    if keep[-1] != len(points) - 1 and np.linalg.norm(points[-1] - points[keep[-1]]) > 1e-9:
        keep[-1] = len(points) - 1
    return points[keep]


def bspline_to_bezier(tck, u_start: float, u_end: float) -> np.ndarray:
    """Bézier control points (K, 4, 2) of a parametric cubic spline between two parameters.

    Each knot span of a cubic spline is one cubic polynomial, so its Bézier form follows
    exactly from the end points and end derivatives (Hermite to Bézier); this works for
    periodic splines as well as open ones.
    """
    knots = np.unique(tck[0])
    breaks = np.unique(np.concatenate([[u_start, u_end], knots[(knots > u_start) & (knots < u_end)]]))
    a, b = breaks[:-1], breaks[1:]
    # Evaluate just inside each span so the derivative belongs to that span's polynomial.
    pa = np.array(splev(a, tck)).T
    pb = np.array(splev(b, tck)).T
    da = np.array(splev(a, tck, der=1)).T
    db = np.array(splev(b, tck, der=1)).T
    h = (b - a)[:, None] / 3.0
    return np.stack([pa, pa + h * da, pb - h * db, pb], axis=1)


def fit_piece(points: np.ndarray, *, closed: bool, sigma: float) -> np.ndarray:
    """Fit one piece: (N, 2) ordered points -> Bézier control points (K, 4, 2).

    sigma: expected noise of the points in px; the smoothing allows that much residual.
    """
    points = _dedupe(points, 1e-3)
    if closed and len(points) > 3 and np.linalg.norm(points[0] - points[-1]) < 1e-6:
        points = points[:-1]
    if len(points) < 4 or (closed and len(points) < 6):
        line = points if len(points) >= 2 else np.vstack([points, points + 1e-3])
        if closed:
            line = np.vstack([line, line[:1]])
        return Stroke.from_polyline(line).control
    if closed:
        points = np.vstack([points, points[:1]])
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    u = np.concatenate([[0.0], np.cumsum(steps)])
    u /= u[-1]
    smoothing = len(points) * sigma * sigma
    try:
        tck, _ = splprep([points[:, 0], points[:, 1]], u=u, k=3, s=smoothing, per=1 if closed else 0, quiet=2)
    except (ValueError, TypeError):
        return Stroke.from_polyline(points).control
    control = bspline_to_bezier(tck, 0.0, 1.0)
    if not closed:
        # Anchor the ends on the data: strokes must start and end where the ink does.
        control[0, 1] += points[0] - control[0, 0]
        control[0, 0] = points[0]
        control[-1, 2] += points[-1] - control[-1, 3]
        control[-1, 3] = points[-1]
    else:
        control[-1, 3] = control[0, 0]
    return control


def fit_stroke(traced: list[TracedPoint], *, closed: bool, sigma: float) -> Stroke:
    """Filter, split at sharp features and fit one traversed stroke."""
    xy = np.array([p.xy for p in traced])
    keep = np.array([p.keep for p in traced])
    split = np.array([p.split for p in traced])
    split_at = np.flatnonzero(split)
    if closed and split_at.size:
        # Start a closed stroke at its first sharp feature: then it is a chain of open pieces.
        shift = int(split_at[0])
        xy, keep, split = (np.roll(a, -shift, axis=0) for a in (xy, keep, split))
        xy, keep, split = np.vstack([xy, xy[:1]]), np.append(keep, True), np.append(split, True)
        closed = False
    cuts = [0] + [int(i) for i in np.flatnonzero(split) if 0 < i < len(xy) - 1] + [len(xy) - 1]
    pieces = []
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        mask = keep[lo:hi + 1].copy()
        if not closed:
            mask[0] = mask[-1] = True
        piece = xy[lo:hi + 1][mask]
        pieces.append(fit_piece(piece, closed=closed and len(cuts) == 2, sigma=sigma))
    control = np.concatenate(pieces, axis=0)
    return Stroke(control)
