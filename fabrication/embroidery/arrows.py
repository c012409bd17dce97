"""Arrow motifs along the curve (paper Fig. 13 right): chevrons pointing the way it is drawn.

A centre walk (running stitch) carries the thread along the curve; at every `spacing` of
arc length it stops on a tip and sews a chevron: out to the left arm, back to the tip,
out to the right arm, back to the tip, then walks on. Tips sit on a grid of arc length
counted over the whole drawing (`offset`), so the motifs never start over at a stroke
boundary. Motifs shrink where the curve under them is tight, and shrink or drop out
before a corner or the start of a stroke instead of reaching across it.
The tip is never pierced twice in a row of holes: the walk arrives `shift` before the
tip, the arms return to the tip and to `shift` past it, and the walk goes on from there
(three holes 0.35 mm apart along the curve instead of one hole pierced three times).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.needles import BODY, GRID, MOTIF, NeedlePoints
from fabrication.embroidery.running import (CORNER_ANGLE, DENSE_TOLERANCE, STITCH_LENGTH, TOLERANCE,
                                            TOLERANCE_RESERVE, RunningOptions, refine_to_tolerance,
                                            stitch_lengths_along)
from fabrication.embroidery.sampling import dense_curve
from fabrication.embroidery.zigzag import SPACING, STITCH_WIDTH
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import Stroke


# Arm length along the curve; and the smallest motif, as a fraction of full size.
ARROW_SIZE = Range(GRID, 20.0, unit="mm", name="--arrow-size")
MIN_SCALE = Range(0.0, 1.0, name="arrow min_scale", low_open=True)

@dataclass(frozen=True, kw_only=True)
class ArrowOptions:
    """size: arm length along the curve, mm; width: tip-to-tip spread of the arms, mm;
    spacing: arc length between tips, mm; stitch_length / tolerance / corner_angle: the
    centre walk; min_scale: smallest motif (fraction of full size) before one is dropped;
    tight_radius: motifs shrink where the curve radius under them is below
    tight_radius x size; shift: distance along the curve between the three holes at a
    tip, mm."""

    size: float = ranged(2.0, ARROW_SIZE)
    width: float = ranged(2.5, STITCH_WIDTH)
    spacing: float = ranged(5.0, SPACING)
    stitch_length: float = ranged(2.5, STITCH_LENGTH)
    tolerance: float = ranged(0.2, TOLERANCE)
    corner_angle: float = ranged(45.0, CORNER_ANGLE)
    min_scale: float = ranged(0.4, MIN_SCALE)
    tight_radius: float = 1.5
    shift: float = 0.35

    def __post_init__(self) -> None:
        check_ranges(self)
        if not self.spacing > self.size:
            raise InputError(f"--spacing {self.spacing:g} mm must exceed --arrow-size {self.size:g} mm, "
                             "or the motifs overlap")

    @property
    def running(self) -> RunningOptions:
        return RunningOptions(stitch_length=self.stitch_length, tolerance=self.tolerance,
                              corner_angle=self.corner_angle)


def arrow_stitch(stroke: Stroke, options: ArrowOptions = ArrowOptions(), *,
                 offset: float = 0.0) -> NeedlePoints:
    """Chevrons along `stroke` (mm). `offset`: arc length of the drawing sewn before this
    stroke, which keeps the motif rhythm continuous from stroke to stroke."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)
    length = curve.length
    # Tips on the global grid size + k * spacing, in this stroke's arc length.
    first = options.size - offset
    k0 = int(np.ceil((0.0 - first) / options.spacing - 1e-9))
    tips = first + options.spacing * np.arange(k0, k0 + int(length // options.spacing) + 2)
    tips = tips[(tips > 0) & (tips <= length)]
    # Tight curves: the smallest radius over each motif's reach scales it down.
    corner = np.abs(curve.turns) > np.radians(options.corner_angle)
    radius = 1.0 / np.maximum(np.abs(curve.curvature), 1e-12)
    reach_lo = np.searchsorted(curve.s, tips - options.size)
    reach_hi = np.searchsorted(curve.s, tips, side="right")
    free = np.where(corner, np.inf, radius)  # a corner is handled as a barrier below
    # Smallest radius in each motif's window [lo, hi) of dense vertices (empty -> inf).
    # Windows do not overlap (spacing > size), so [lo0, hi0, lo1, hi1, ...] is sorted and
    # every other reduceat result is one window's minimum.
    padded = np.append(free, np.inf)
    bounds = np.minimum(np.column_stack([reach_lo, reach_hi]).ravel(), len(free))
    smallest = np.minimum.reduceat(padded, bounds)[::2] if len(bounds) else np.zeros(0)
    smallest[reach_hi <= reach_lo] = np.inf
    scale = np.minimum(1.0, smallest / (options.tight_radius * options.size))
    # The arms must not reach back across a corner or the start of the stroke.
    barrier = np.concatenate([[0.0], curve.s[corner]])
    last = barrier[np.maximum(np.searchsorted(barrier, tips - 1e-9) - 1, 0)]
    scale = np.minimum(scale, (tips - last) / options.size)
    ok = scale >= options.min_scale
    tips, scale = tips[ok], scale[ok]

    # The walk arrives `shift` before each tip and leaves from `shift` past it.
    arrive = np.maximum(tips - options.shift, 0.0)
    leave = np.minimum(tips + options.shift, length)
    s = stitch_lengths_along(curve, options.running, breaks=arrive)
    s, t = refine_to_tolerance(stroke, curve, s, options.tolerance - TOLERANCE_RESERVE)
    if len(tips):
        # Walk points between an arrival and `shift` past the leaving hole would pierce
        # next to the tip's holes: the motif's last hole stands in for them.
        slot = np.searchsorted(arrive, s, side="right") - 1
        near = (slot >= 0) & (s > arrive[np.maximum(slot, 0)] + 1e-9) & \
            (s <= leave[np.maximum(slot, 0)] + options.shift)
        near[-1] = False  # the stroke's end stays
        s, t = s[~near], t[~near]
    walk = NeedlePoints.of(stroke.points_at(t), t, BODY)
    if not len(tips):
        return walk
    arrive_index = np.searchsorted(s, arrive - 1e-9)
    base_t = curve.t_at(tips - options.size * scale)
    tip_t = curve.t_at(tips)
    leave_t = curve.t_at(leave)
    base = stroke.points_at(base_t)
    tangent = stroke.tangents_at(base_t)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    half = (options.width / 2.0 * scale)[:, None]
    tip = stroke.points_at(tip_t)
    motif = np.stack([base + normal * half, tip, base - normal * half, stroke.points_at(leave_t)], axis=1)
    motif_t = np.stack([base_t, tip_t, base_t, leave_t], axis=1)
    where = np.repeat(arrive_index + 1, 4)
    return NeedlePoints(np.insert(walk.points, where, motif.reshape(-1, 2), axis=0),
                        np.insert(walk.t, where, motif_t.ravel()),
                        np.insert(walk.roles, where, np.full(where.size, MOTIF, dtype=np.uint8)))
