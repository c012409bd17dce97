"""GRBL's arc expander (motion_control.c `mc_arc`): a G2/G3 arc as the chords GRBL plans.

The number of chords keeps each one within the arc tolerance `$12` of the true arc:
n = floor(|sweep| r / 2 / sqrt(e (2r - e))). Points are computed exactly (GRBL rotates a
vector with a small-angle approximation and corrects it every 12 chords; the difference
is far below a step).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

ARC_ANGULAR_TRAVEL_EPSILON = 5e-7


@dataclass(frozen=True)
class ArcChords:
    """points: chord end points, each (3,) mm, the last one the arc's target; sweep: signed
    angle travelled (radians, negative clockwise)."""

    points: tuple[tuple[float, float, float], ...]
    sweep: float


def arc_chords(start: Sequence[float], target: Sequence[float], offset: Sequence[float], radius: float,
               axes: tuple[int, int, int], clockwise: bool, tolerance: float) -> ArcChords:
    """Chords of the arc from `start` to `target` (3,) mm around start + offset.

    axes: (first, second, linear) axis indices of the plane (G17: (0, 1, 2)); radius mm;
    tolerance: `$12` in mm.
    """
    a0, a1, lin = axes
    center0, center1 = start[a0] + offset[a0], start[a1] + offset[a1]
    r0, r1 = -offset[a0], -offset[a1]
    rt0, rt1 = target[a0] - center0, target[a1] - center1
    sweep = math.atan2(r0 * rt1 - r1 * rt0, r0 * rt0 + r1 * rt1)
    if clockwise and sweep >= -ARC_ANGULAR_TRAVEL_EPSILON:
        sweep -= 2 * math.pi
    elif not clockwise and sweep <= ARC_ANGULAR_TRAVEL_EPSILON:
        sweep += 2 * math.pi
    segments = 0
    if radius > tolerance:
        segments = int(math.floor(abs(0.5 * sweep * radius) / math.sqrt(tolerance * (2 * radius - tolerance))))
    points = []
    for i in range(1, segments):
        theta = sweep * i / segments
        c, s = math.cos(theta), math.sin(theta)
        point = list(start)
        point[a0] = center0 + r0 * c - r1 * s
        point[a1] = center1 + r0 * s + r1 * c
        point[lin] = start[lin] + (target[lin] - start[lin]) * i / segments
        points.append(tuple(point))
    points.append(tuple(float(v) for v in target))
    return ArcChords(tuple(points), sweep)
