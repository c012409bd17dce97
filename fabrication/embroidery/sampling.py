"""Dense sampling of a stroke: a fine polyline with parameters, arc lengths, turns and curvature.

Stitch generators measure the curve on this polyline (corners, radius, chord error) and
then place needle points on the exact curve through the parameter `t`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from vectorize.stroke import Stroke, arc_lengths


@dataclass(frozen=True, eq=False)
class DenseCurve:
    """points (M, 2) mm on the curve, their parameters t (M,) and arc lengths s (M,),
    s[0] = 0, strictly increasing (repeated points are removed)."""

    points: np.ndarray
    t: np.ndarray
    s: np.ndarray

    @property
    def length(self) -> float:
        return float(self.s[-1])

    @cached_property
    def directions(self) -> np.ndarray:
        """Unit direction of each polyline piece: (M - 1, 2)."""
        d = np.diff(self.points, axis=0)
        return d / np.diff(self.s)[:, None]

    @cached_property
    def turns(self) -> np.ndarray:
        """Signed turning angle in radians at each vertex (M,); 0 at both ends.
        Positive turns towards the normal (-dy, dx) of the travel direction."""
        d = self.directions
        cross = d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]
        dot = np.einsum("ij,ij->i", d[:-1], d[1:])
        return np.concatenate([[0.0], np.arctan2(cross, dot), [0.0]])

    @cached_property
    def curvature(self) -> np.ndarray:
        """Signed curvature 1/mm at each vertex (M,): turn over the mean neighbouring piece."""
        ds = np.diff(self.s)
        half = np.zeros(len(self.s))
        half[1:-1] = 0.5 * (ds[:-1] + ds[1:])
        return np.divide(self.turns, half, out=np.zeros_like(half), where=half > 0)

    def t_at(self, s: np.ndarray) -> np.ndarray:
        """Parameters at arc lengths `s` (interpolated on the dense polyline)."""
        return np.interp(s, self.s, self.t)


def dense_curve(stroke: Stroke, tolerance: float = 0.005) -> DenseCurve:
    """Sample `stroke` (mm) finely: chords stay within `tolerance` mm of the curve.

    Uses the same per-segment step count as `Stroke.flatten` (Wang's formula) so that every
    segment joint, where sharp corners sit, is a vertex.
    """
    c = stroke.control
    second = np.maximum(np.linalg.norm(c[:, 0] - 2 * c[:, 1] + c[:, 2], axis=1),
                        np.linalg.norm(c[:, 1] - 2 * c[:, 2] + c[:, 3], axis=1))
    steps = np.maximum(1, np.ceil(np.sqrt(0.75 * second / tolerance))).astype(int)
    index = np.repeat(np.arange(len(c)), steps)
    offsets = np.arange(index.size) - np.repeat(np.cumsum(steps) - steps, steps)
    t = np.append((index + offsets / np.repeat(steps, steps)) / len(c), 1.0)
    points = stroke.points_at(t)
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    # Coincident control points give zero-length pieces; they carry no direction.
    keep = np.concatenate([[True], seg > 1e-9])
    if keep.sum() < 2:
        keep[-1] = True
    points, t = points[keep], t[keep]
    s = arc_lengths(points)
    if s[-1] <= 0:
        s[-1] = 1e-9
    return DenseCurve(points, t, s)
