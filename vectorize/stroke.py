"""`Stroke`: one cubic Bézier spline, the geometric type that travels through onestroke."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from onestroke.errors import InputError

# Samples per Bézier segment of the arc-length table; the chord error this leaves in the
# length is below 1e-5 of the segment length for the gentle segments spline fitting makes.
_TABLE_SAMPLES = 48

# Largest coordinate a stroke may hold (px before placement, mm after): ten million units
# keeps squared lengths and arc-length sums far from overflow and every number written out
# short. Readers refuse or clamp beyond it, naming the element.
MAX_COORDINATE = 1e7


def edge_lengths(points: np.ndarray) -> np.ndarray:
    """(M, 2) points -> (M-1,) distances between successive points (px).

    The same numbers as `np.linalg.norm(np.diff(points, axis=0), axis=1)` (that is how it
    sums the squares), without its overhead: this runs on a thousand small arrays per drawing.
    """
    return lengths(points[1:] - points[:-1])


def lengths(vectors: np.ndarray) -> np.ndarray:
    """(N, 2) vectors -> (N,) their lengths: the same numbers as `np.linalg.norm(vectors,
    axis=1)` (the two squares summed, then rooted), at a tenth of its cost on long arrays
    (numpy's reduction over an axis of two is slow)."""
    return np.sqrt(vectors[:, 0] * vectors[:, 0] + vectors[:, 1] * vectors[:, 1])


def arc_lengths(points: np.ndarray) -> np.ndarray:
    """(M, 2) points -> (M,) arc length at each point along the polyline, 0 at the first."""
    return np.concatenate([[0.0], np.cumsum(edge_lengths(points))])


def _bezier_points(control: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Evaluate cubic segments. control (K, 4, 2), t (M,) in [0, 1] -> (K, M, 2)."""
    t = t[None, :, None]
    u = 1.0 - t
    p0, p1, p2, p3 = (control[:, i, None, :] for i in range(4))
    return u * u * u * p0 + 3 * u * u * t * p1 + 3 * u * t * t * p2 + t * t * t * p3


def curve_bounds(control: np.ndarray) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of cubic segments `control` (K, 4, 2), of any number of
    strokes at once (`Drawing.bounds` stacks them: one pass instead of one per stroke)."""
    control = np.asarray(control, dtype=float)
    p0, p1, p2, p3 = (control[:, i] for i in range(4))
    a = -p0 + 3 * p1 - 3 * p2 + p3  # B'(t) / 3 = a t^2 + 2 b t + c, per segment and axis
    b = p0 - 2 * p1 + p2
    c = p1 - p0
    disc = b * b - a * c
    root = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = np.abs(a) < 1e-12
        t = np.stack([np.where(linear, -c / (2 * b), (-b + root) / a),
                      np.where(linear, np.nan, (-b - root) / a)], axis=-1)
    inside = (t > 0) & (t < 1) & (disc[..., None] >= 0)
    t = np.where(inside, t, 0.0)
    u = 1 - t
    values = (u**3 * p0[..., None] + 3 * u * u * t * p1[..., None]
              + 3 * u * t * t * p2[..., None] + t**3 * p3[..., None])
    values = np.where(inside, values, p0[..., None])
    lo = np.minimum(np.minimum(p0, p3).min(axis=0), values.min(axis=(0, 2)))
    hi = np.maximum(np.maximum(p0, p3).max(axis=0), values.max(axis=(0, 2)))
    return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def checked_widths(widths) -> np.ndarray:
    """A width profile (see `Stroke`) as a read-only (M, 2) float array, or `InputError`."""
    widths = np.array(widths, dtype=float)
    if widths.ndim != 2 or widths.shape[1] != 2 or len(widths) < 2:
        raise InputError(f"stroke widths must have shape (M >= 2, 2) rows (t, width), got {widths.shape}")
    if not np.all(np.isfinite(widths)):
        raise InputError("stroke widths must be finite numbers")
    t, w = widths[:, 0], widths[:, 1]
    if abs(t[0]) > 1e-9 or abs(t[-1] - 1.0) > 1e-9 or np.any(np.diff(t) <= 0):
        raise InputError("stroke widths' parameters must rise strictly from 0 to 1")
    if w.min() < 0 or w.max() > MAX_COORDINATE:
        raise InputError(f"stroke widths must lie in [0, {MAX_COORDINATE:.0e}], got {w.min():.3g}-{w.max():.3g}")
    widths[0, 0], widths[-1, 0] = 0.0, 1.0
    widths.setflags(write=False)
    return widths


def scaled_widths(widths: np.ndarray | None, matrix: np.ndarray) -> np.ndarray | None:
    """A width profile through the 2x3 affine `matrix`: widths times the square root of its
    area scale (the exact factor of a uniform scale, a rotation or a mirror)."""
    if widths is None:
        return None
    (a, b, _), (c, d, _) = np.asarray(matrix, dtype=float)
    return np.column_stack([widths[:, 0], widths[:, 1] * np.sqrt(abs(a * d - b * c))])


def recut_widths(widths: np.ndarray | None, old: np.ndarray, new: np.ndarray) -> np.ndarray | None:
    """A width profile for a re-cut curve: `old` (B,) the old global parameters, rising (they
    may run past 1 on a closed curve re-started elsewhere: taken modulo 1), of the new
    curve's parameters `new` (B,) rising from 0 to 1, between which both run linearly."""
    if widths is None:
        return None
    old, new = np.asarray(old, dtype=float), np.asarray(new, dtype=float)
    # the old profile's rows, as old parameters within [old[0], old[-1]] (and a turn on)
    rows = np.concatenate([widths[:, 0] + k for k in range(int(np.floor(old[0])), int(np.ceil(old[-1])) + 1)])
    rows = rows[(rows > old[0]) & (rows < old[-1])]
    t_old = np.union1d(old, rows)
    t_new = np.interp(t_old, old, new)
    keep = np.concatenate([[True], np.diff(t_new) > 1e-12])
    t_old, t_new = t_old[keep], t_new[keep]
    t_new[-1] = 1.0
    return np.column_stack([t_new, np.interp(np.mod(t_old, 1.0) if old[-1] > 1.0 else t_old,
                                             widths[:, 0], widths[:, 1])])


@dataclass(frozen=True, eq=False)
class Stroke:
    """A cubic Bézier spline: `control` has shape (K, 4, 2), x right, y down.

    Segment k runs from control[k, 0] to control[k, 3]; consecutive segments share end
    points. The global parameter t in [0, 1] maps uniformly onto the K segments. Units are
    those of the `Drawing` that holds the stroke (px before placement, mm after).
    `color`: RGB 0-255 the stroke is drawn in (an SVG stroke colour), None when unknown;
    it travels with the curve through reversal and transforms.
    `widths`: the ink width along the stroke, (M >= 2, 2) rows (t, width): global parameter
    t rising strictly from 0 to 1, width >= 0 in the drawing's unit (the vectorizer's
    medial-axis diameter), linear between rows; None when unknown (the drawing's
    `stroke_width` stands in). It travels with the curve too: reversed, scaled by the
    transform's area scale, re-cut with the segments.
    """

    control: np.ndarray
    color: tuple[int, int, int] | None = None
    widths: np.ndarray | None = None

    def __post_init__(self) -> None:
        control = np.array(self.control, dtype=float)
        if control.ndim != 3 or control.shape[1:] != (4, 2) or len(control) == 0:
            raise InputError(f"stroke control points must have shape (K, 4, 2), got {control.shape}")
        largest = np.abs(control).max()
        if not largest <= MAX_COORDINATE:  # one pass: NaN and infinity fail this test too
            if not np.all(np.isfinite(control)):
                raise InputError("stroke control points must be finite numbers")
            raise InputError(f"stroke coordinate {largest:.3g} is beyond the limit of "
                             f"{MAX_COORDINATE:.0e} (px or mm)")
        control.setflags(write=False)
        object.__setattr__(self, "control", control)
        if self.color is not None:
            color = tuple(int(c) for c in self.color)
            if len(color) != 3 or not all(0 <= c <= 255 for c in color):
                raise InputError(f"stroke colour {self.color!r} must be three values 0-255")
            object.__setattr__(self, "color", color)
        if self.widths is not None:
            object.__setattr__(self, "widths", checked_widths(self.widths))

    # -- construction ------------------------------------------------------------------
    @classmethod
    def from_polyline(cls, points: np.ndarray) -> "Stroke":
        """A stroke of straight cubic segments through `points` (N >= 2, 2)."""
        points = np.asarray(points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 2 or len(points) < 2:
            raise InputError(f"a polyline needs shape (N >= 2, 2), got {points.shape}")
        a, b = points[:-1], points[1:]
        return cls(np.stack([a, a + (b - a) / 3.0, a + 2.0 * (b - a) / 3.0, b], axis=1))

    # -- basic properties --------------------------------------------------------------
    @property
    def segment_count(self) -> int:
        return len(self.control)

    @property
    def start(self) -> np.ndarray:
        return self.control[0, 0]

    @property
    def end(self) -> np.ndarray:
        return self.control[-1, 3]

    @property
    def is_closed(self) -> bool:
        """True when the end point meets the start point (within 1e-6 of the size)."""
        scale = max(1.0, float(np.ptp(self.control.reshape(-1, 2), axis=0).max()))
        return bool(np.linalg.norm(self.end - self.start) <= 1e-6 * scale)

    @cached_property
    def _table(self) -> tuple[np.ndarray, np.ndarray]:
        """(t, s): global parameters and cumulative arc lengths of a dense sampling."""
        local = np.linspace(0.0, 1.0, _TABLE_SAMPLES + 1)
        pts = _bezier_points(self.control, local)[:, :-1].reshape(-1, 2)
        pts = np.vstack([pts, self.end])
        t = np.concatenate(
            [(k + local[:-1]) / self.segment_count for k in range(self.segment_count)] + [[1.0]]
        )
        s = arc_lengths(pts)
        return t, s

    @property
    def length(self) -> float:
        """Arc length of the whole spline."""
        return float(self._table[1][-1])

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the curve itself (not of its control polygon).

        Exact: the end points of every segment and its interior extremes, where the
        derivative (a quadratic per axis) vanishes.
        """
        return curve_bounds(self.control)

    # -- evaluation --------------------------------------------------------------------
    def _split_parameter(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        scaled = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * self.segment_count
        index = np.minimum(scaled.astype(int), self.segment_count - 1)
        return index, scaled - index

    def points_at(self, t: np.ndarray | float) -> np.ndarray:
        """Points at global parameters t in [0, 1]: shape (M, 2) (or (2,) for a scalar)."""
        scalar = np.ndim(t) == 0
        index, local = self._split_parameter(np.atleast_1d(t))
        c = self.control[index]
        u = (1.0 - local)[:, None]
        v = local[:, None]
        out = u**3 * c[:, 0] + 3 * u * u * v * c[:, 1] + 3 * u * v * v * c[:, 2] + v**3 * c[:, 3]
        return out[0] if scalar else out

    def tangents_at(self, t: np.ndarray | float) -> np.ndarray:
        """Unit tangents (direction of travel) at global parameters t: shape (M, 2)."""
        scalar = np.ndim(t) == 0
        index, local = self._split_parameter(np.atleast_1d(t))
        c = self.control[index]
        u = (1.0 - local)[:, None]
        v = local[:, None]
        d = 3 * u * u * (c[:, 1] - c[:, 0]) + 6 * u * v * (c[:, 2] - c[:, 1]) + 3 * v * v * (c[:, 3] - c[:, 2])
        # A degenerate derivative (coincident control points) falls back to the chord.
        chord = c[:, 3] - c[:, 0]
        small = np.linalg.norm(d, axis=1) < 1e-12
        d[small] = chord[small]
        norm = np.linalg.norm(d, axis=1, keepdims=True)
        out = np.divide(d, norm, out=np.zeros_like(d), where=norm > 0)
        return out[0] if scalar else out

    def parameters_at_lengths(self, s: np.ndarray | float) -> np.ndarray:
        """Global parameters t at arc lengths s (clipped to [0, length])."""
        t_table, s_table = self._table
        return np.interp(np.clip(s, 0.0, self.length), s_table, t_table)

    def points_at_lengths(self, s: np.ndarray | float) -> np.ndarray:
        """Points at arc lengths s from the start: shape (M, 2)."""
        return self.points_at(self.parameters_at_lengths(s))

    def sample_evenly(self, spacing: float) -> np.ndarray:
        """Points every `spacing` of arc length, start and end included: shape (M, 2).

        The spacing is adjusted down so that the points divide the length equally.
        """
        if not spacing > 0:
            raise InputError(f"sampling spacing must be > 0, got {spacing}")
        count = max(1, int(np.ceil(self.length / spacing - 1e-9)))
        return self.points_at_lengths(np.linspace(0.0, self.length, count + 1))

    def flatten(self, tolerance: float) -> np.ndarray:
        """A polyline within `tolerance` of the curve: shape (N, 2), start and end included.

        Each segment is cut into n equal parameter steps with n from Wang's formula,
        n = ceil(sqrt(3/4 * M / tolerance)), M = largest second difference of its control
        points, which bounds the chord error of every piece by `tolerance`.
        """
        if not tolerance > 0:
            raise InputError(f"flattening tolerance must be > 0, got {tolerance}")
        c = self.control
        second = np.maximum(
            np.linalg.norm(c[:, 0] - 2 * c[:, 1] + c[:, 2], axis=1),
            np.linalg.norm(c[:, 1] - 2 * c[:, 2] + c[:, 3], axis=1),
        )
        steps = np.maximum(1, np.ceil(np.sqrt(0.75 * second / tolerance))).astype(int)
        index = np.repeat(np.arange(len(c)), steps)
        # local parameter j / n for j = 0..n-1 of each segment
        offsets = np.arange(index.size) - np.repeat(np.cumsum(steps) - steps, steps)
        local = offsets / np.repeat(steps, steps)
        t = (index + local) / len(c)
        pts = self.points_at(np.append(t, 1.0))
        return pts

    # -- ink width ----------------------------------------------------------------------
    def widths_at(self, t: np.ndarray | float) -> np.ndarray | None:
        """Ink widths at global parameters t (same shape as t), None when unknown."""
        if self.widths is None:
            return None
        return np.interp(t, self.widths[:, 0], self.widths[:, 1])

    def with_widths(self, widths: np.ndarray | None) -> "Stroke":
        """The same curve with another width profile (see the class doc)."""
        return Stroke(self.control, self.color, widths)

    # -- transformations ---------------------------------------------------------------
    def reversed(self) -> "Stroke":
        """The same curve traversed from end to start."""
        widths = None
        if self.widths is not None:
            widths = np.column_stack([1.0 - self.widths[::-1, 0], self.widths[::-1, 1]])
            widths[0, 0], widths[-1, 0] = 0.0, 1.0
        return Stroke(self.control[::-1, ::-1], self.color, widths)

    def transformed(self, matrix: np.ndarray) -> "Stroke":
        """Apply a 2x3 affine matrix [[a, b, tx], [c, d, ty]] to every control point."""
        (a, b, tx), (c, d, ty) = np.asarray(matrix, dtype=float)
        x, y = self.control[..., 0], self.control[..., 1]
        # Written out: a batched (K*4, 2) @ (2, 2) matmul is several times slower.
        return Stroke(np.stack([a * x + b * y + tx, c * x + d * y + ty], axis=-1), self.color,
                      scaled_widths(self.widths, matrix))
