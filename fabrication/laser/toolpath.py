"""Toolpath planning: a `Drawing` becomes burn paths in the laser's machine frame.

Steps: place (mm, size, rotation) -> flip y (screen y down -> machine y up, so the
engraving is not mirrored) -> move to the origin -> check the bed -> flatten each stroke
within the tolerance (lines simplified by Douglas-Peucker, or lines and G2/G3 arcs) ->
quantize to the 0.001 mm the G-code carries and drop zero-length moves -> order and
orient the strokes to cut travel.

Tolerance budget (all in mm, `tolerance` = t): Wang's-formula flattening within t/4, then
simplification or arc fitting within 3t/4 - 0.001, then rounding to 0.001 mm (at most
0.0007 off). The sum stays within t of the input curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from fabrication.laser.arcs import CCW, CW, LINE, fit_arcs
from fabrication.laser.travel_order import order_strokes, travel_length
from fabrication.placement import PlacementOptions, place
from machines.laser_profile import LaserProfile
from onestroke.errors import InputError
from onestroke.progress import ProgressCallback, counted
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

ORIGINS = ("lower-left", "center")
# Largest distance of the burned path from the drawing: at least 5 G-code quanta (the
# rounding budget must leave room), at most 1 mm (coarser is no longer the drawing).
TOLERANCE = Range(0.005, 1.0, unit="mm", name="--tolerance")
QUANTUM = 0.001  # mm: G-code numbers carry 3 decimals
_ROUNDING_BUDGET = 0.001  # covers sqrt(2) * QUANTUM / 2 with margin


@dataclass(frozen=True, kw_only=True)
class ToolpathOptions:
    """placement: size and rotation of the design (mm).
    origin: "lower-left" puts the design's lower-left corner at machine (0, 0); "center"
    puts its centre at the centre of the bed.
    tolerance: largest distance (mm) of the burned path from the drawing's curves.
    arcs: fit G2/G3 arcs within the tolerance (fewer lines) instead of only lines.
    optimize: reorder and reverse strokes to shorten travel (False keeps drawing order).
    """

    placement: PlacementOptions = PlacementOptions()
    origin: str = "lower-left"
    tolerance: float = ranged(0.02, TOLERANCE)
    arcs: bool = False
    optimize: bool = True

    def __post_init__(self) -> None:
        check_ranges(self)
        if self.origin not in ORIGINS:
            raise InputError(f"origin {self.origin!r} is not one of {', '.join(ORIGINS)}")


@dataclass(frozen=True)
class BurnPath:
    """One beam-on path: vertices (N, 2) mm machine frame; kinds (N-1,) int8 (1 G1,
    2 G2 clockwise, 3 G3 counter-clockwise); centres (N-1, 2) arc centres (NaN for lines).
    """

    points: np.ndarray
    kinds: np.ndarray
    centres: np.ndarray

    @property
    def segment_count(self) -> int:
        return len(self.kinds)

    def segment_lengths(self) -> np.ndarray:
        """Length of each move, mm (arcs along the arc)."""
        a, b = self.points[:-1], self.points[1:]
        chord = np.hypot(*(b - a).T)
        arc = self.kinds != LINE
        if not arc.any():
            return chord
        out = chord.copy()
        ra, rb = a[arc] - self.centres[arc], b[arc] - self.centres[arc]
        r = np.hypot(*ra.T)
        sweep = np.arctan2(ra[:, 0] * rb[:, 1] - ra[:, 1] * rb[:, 0], (ra * rb).sum(axis=1))
        ccw = self.kinds[arc] == CCW
        sweep = np.where(ccw & (sweep <= 0), sweep + 2 * np.pi, sweep)
        sweep = np.where(~ccw & (sweep >= 0), sweep - 2 * np.pi, sweep)
        out[arc] = r * np.abs(sweep)
        return out

    def polyline(self, *, max_angle: float = 0.05) -> np.ndarray:
        """The path as a polyline (N, 2), arcs sampled every `max_angle` radians."""
        if not (self.kinds != LINE).any():
            return self.points
        out = [self.points[:1]]
        for k, kind in enumerate(self.kinds.tolist()):
            a, b = self.points[k], self.points[k + 1]
            if kind == LINE:
                out.append(b[None])
                continue
            c = self.centres[k]
            ra, rb = a - c, b - c
            sweep = np.arctan2(ra[0] * rb[1] - ra[1] * rb[0], float(ra @ rb))
            if kind == CCW and sweep <= 0:
                sweep += 2 * np.pi
            if kind == CW and sweep >= 0:
                sweep -= 2 * np.pi
            n = max(2, int(np.ceil(abs(sweep) / max_angle)))
            angles = np.arctan2(ra[1], ra[0]) + sweep * np.arange(1, n + 1) / n
            pts = c + np.hypot(*ra) * np.c_[np.cos(angles), np.sin(angles)]
            pts[-1] = b
            out.append(pts)
        return np.vstack(out)

    @property
    def length(self) -> float:
        return float(self.segment_lengths().sum())

    @property
    def is_closed(self) -> bool:
        return len(self.points) > 2 and bool(np.all(self.points[0] == self.points[-1]))

    def rotated(self, start: int) -> "BurnPath":
        """A closed path started at vertex `start` (same loop, same direction)."""
        if not self.is_closed or start % self.segment_count == 0:
            return self
        k = start % self.segment_count
        points = np.vstack([self.points[k:-1], self.points[:k + 1]])
        return BurnPath(points, np.roll(self.kinds, -k), np.roll(self.centres, -k, axis=0))

    def reversed(self) -> "BurnPath":
        """The same path burned from its end to its start."""
        kinds = self.kinds[::-1].copy()
        swap = kinds != LINE
        kinds[swap] = np.where(kinds[swap] == CW, CCW, CW)
        return BurnPath(self.points[::-1].copy(), kinds, self.centres[::-1].copy())


@dataclass(frozen=True)
class Toolpath:
    """The planned job: burn paths in job order, in mm, machine frame (+y up).

    curves: the placed input strokes in the same frame, order and direction as `paths`
    (for measuring the tolerance). travel_*: beam-off travel (mm) from machine (0, 0)
    in the drawing's order, after the greedy tour and after 2-opt. dropped: strokes of
    zero length left out.
    """

    paths: tuple[BurnPath, ...]
    curves: tuple[Stroke, ...]
    bounds: tuple[float, float, float, float]
    bed: tuple[float, float]
    tolerance: float
    travel_before: float
    travel_greedy: float
    travel_after: float
    dropped: int = 0

    @property
    def burn_length(self) -> float:
        return float(sum(p.length for p in self.paths))

    @property
    def segment_count(self) -> int:
        return int(sum(p.segment_count for p in self.paths))

    @property
    def size(self) -> tuple[float, float]:
        return self.bounds[2] - self.bounds[0], self.bounds[3] - self.bounds[1]


def _to_machine(drawing: Drawing, profile: LaserProfile, options: ToolpathOptions) -> Drawing:
    placed = place(drawing, options.placement)
    # `place` centres the bounding box on (0, 0) and sets the canvas to its size, so the
    # box is known without measuring the curves again (which is slow on long strokes).
    w, h = placed.width, placed.height
    if options.origin == "lower-left":
        tx, ty = w / 2, h / 2
    else:
        tx, ty = profile.bed_width / 2, profile.bed_height / 2
    # y flips here: screen y points down, machine y up; without the flip it would be mirrored
    matrix = np.array([[1.0, 0.0, tx], [0.0, -1.0, ty]])
    return placed.transformed(matrix, width=w, height=h, unit="mm", stroke_width=placed.stroke_width)


def _check_bed(bounds: tuple[float, float, float, float], profile: LaserProfile) -> None:
    xmin, ymin, xmax, ymax = bounds
    slack = QUANTUM / 2
    if xmin < -slack or ymin < -slack or xmax > profile.bed_width + slack or ymax > profile.bed_height + slack:
        raise InputError(
            f"the design ({xmax - xmin:.1f} x {ymax - ymin:.1f} mm at x {xmin:.1f}..{xmax:.1f}, "
            f"y {ymin:.1f}..{ymax:.1f}) does not fit the bed {profile.bed_width:g} x "
            f"{profile.bed_height:g} mm of {profile.name!r}; use a smaller --size or another --profile")


def _dedupe(points: np.ndarray) -> np.ndarray:
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(points[1:] != points[:-1], axis=1)
    return points[keep]


def _quantize(points: np.ndarray) -> np.ndarray:
    # + 0.0 turns -0.0 into 0.0 so that equal positions compare equal
    return np.round(points / QUANTUM) * QUANTUM + 0.0


def _plan_stroke(stroke: Stroke, tolerance: float, arcs: bool, box) -> BurnPath | None:
    dense = _dedupe(_quantize(stroke.flatten(tolerance / 4)))
    if len(dense) < 2:
        return None
    fit_tolerance = 0.75 * tolerance - _ROUNDING_BUDGET
    if arcs:
        points, kinds, centres = fit_arcs(dense, fit_tolerance, quantum=QUANTUM, box=box)
        return BurnPath(points, kinds, centres)
    simple = shapely.get_coordinates(
        shapely.simplify(shapely.linestrings(dense), fit_tolerance, preserve_topology=False))
    points = _dedupe(simple)
    if len(points) < 2:
        # a tiny closed loop can simplify to a single point: keep its first segment at least
        points = dense[[0, -1]] if np.any(dense[0] != dense[-1]) else dense[:2]
    kinds = np.full(len(points) - 1, LINE, dtype=np.int8)
    return BurnPath(points, kinds, np.full((len(points) - 1, 2), np.nan))


def plan_toolpath(drawing: Drawing, profile: LaserProfile,
                  options: ToolpathOptions = ToolpathOptions(), *,
                  progress: ProgressCallback | None = None) -> Toolpath:
    """Place `drawing` on the bed of `profile` and plan its burn paths (see module doc).
    progress: an `onestroke.progress.ProgressCallback` (strokes flattened)."""
    if not drawing.strokes:
        raise InputError("the drawing has no strokes to engrave")
    machine = _to_machine(drawing, profile, options)
    # refuse a design larger than the bed before flattening it (that can take long)
    w, h = machine.width, machine.height
    if w > profile.bed_width + QUANTUM or h > profile.bed_height + QUANTUM:
        x0, y0 = (0.0, 0.0) if options.origin == "lower-left" else (
            (profile.bed_width - w) / 2, (profile.bed_height - h) / 2)
        _check_bed((x0, y0, x0 + w, y0 + h), profile)
    box = (0.0, 0.0, profile.bed_width, profile.bed_height)  # no arc may bulge out of the bed
    planned: list[tuple[BurnPath, Stroke]] = []
    dropped = 0
    for stroke in counted(machine.strokes, progress, "flattening", len(machine.strokes), "strokes"):
        path = _plan_stroke(stroke, options.tolerance, options.arcs, box)
        if path is None:
            dropped += 1
        else:
            planned.append((path, stroke))
    if not planned:
        raise InputError("every stroke of the drawing has zero length; nothing to engrave")
    # the bed check runs on what will be burned, arcs included: that is what must stay inside
    everything = np.vstack([p.polyline(max_angle=0.01) for p, _ in planned])
    bounds = (*map(float, everything.min(axis=0)), *map(float, everything.max(axis=0)))
    _check_bed(bounds, profile)
    starts = np.array([p.points[0] for p, _ in planned])
    ends = np.array([p.points[-1] for p, _ in planned])
    if options.optimize:
        result = order_strokes(starts, ends, origin=(0.0, 0.0), progress=progress)
        order, flipped = result.order, result.flipped
        before, greedy, after = result.before, result.greedy, result.after
    else:
        order, flipped = np.arange(len(planned)), np.zeros(len(planned), dtype=bool)
        before = greedy = after = travel_length(starts, ends, np.zeros(2))
    paths, curves = [], []
    position = np.zeros(2)
    for index, flip in zip(order.tolist(), flipped.tolist()):
        path, stroke = planned[index]
        path = path.reversed() if flip else path
        if options.optimize and path.is_closed:
            # a closed loop may start at any vertex: take the one nearest the head
            path = path.rotated(int(np.argmin(np.hypot(*(path.points - position).T))))
        paths.append(path)
        curves.append(stroke.reversed() if flip else stroke)
        position = path.points[-1]
    if options.optimize:
        after = travel_length(np.array([p.points[0] for p in paths]), np.array([p.points[-1] for p in paths]),
                              np.zeros(2))
    return Toolpath(tuple(paths), tuple(curves), bounds, (profile.bed_width, profile.bed_height),
                    options.tolerance, before, greedy, after, dropped)
