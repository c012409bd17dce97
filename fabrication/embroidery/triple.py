"""Triple (bean) stitch: each running stitch is sewn forward, back and forward again.

`repeats` back-and-forth passes per stitch: 1 repeat = 3 layers of thread, the bold
"backstitch" look of the paper's Fig. 1. The needle never goes into the hole it made
two penetrations before: a needle entering a fresh hole beside threads already there
lays them side by side, one entering the same hole again cuts or piles them. Each return
pass stops `shift` short of the hole it returns to, and each forward pass `shift` past
the hole it goes to, so the holes of one base point lie `shift` apart along the curve
(0.35 mm: still >= 0.2 mm after the files' 0.1 mm grid). A stitch too short to hold the
shifted holes is sewn once (as running stitch); the third layer rounds a sharp corner
by at most `shift`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.needles import BODY, NeedlePoints
from fabrication.embroidery.running import (CORNER_ANGLE, DENSE_TOLERANCE, FRESH_HOLE, STITCH_LENGTH,
                                            TOLERANCE, RunningOptions, running_stitch)
from fabrication.embroidery.sampling import dense_curve
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import Stroke

REPEATS = Range(1, 5, name="--repeats", integer=True)
SHIFT = Range(0.2, 2.0, unit="mm", name="triple-stitch shift")


@dataclass(frozen=True, kw_only=True)
class TripleOptions:
    """Running-stitch placement (mm, degrees) plus `repeats` back-and-forth passes and
    `shift`: how far (mm, along the curve) the holes of the passes lie from each other."""

    stitch_length: float = ranged(2.5, STITCH_LENGTH)
    tolerance: float = ranged(0.2, TOLERANCE)
    corner_angle: float = ranged(45.0, CORNER_ANGLE)
    repeats: int = ranged(1, REPEATS)
    shift: float = ranged(0.35, SHIFT)

    def __post_init__(self) -> None:
        check_ranges(self)

    @property
    def running(self) -> RunningOptions:
        return RunningOptions(stitch_length=self.stitch_length, tolerance=self.tolerance,
                              corner_angle=self.corner_angle)


def bean_lengths(base: np.ndarray, repeats: int, shift: float) -> np.ndarray:
    """Arc lengths of the bean stitch's needle points over base points at arc lengths
    `base` (n,): for each stitch, forward to its end, then `r` times back to `shift` x r
    past where it started and forward to `shift` x r past its end; fewer passes where the
    stitch is too short for them."""
    out = [float(base[0])]
    here = float(base[0])
    n = len(base)
    for k in range(1, n):
        end = float(base[k])
        out.append(end)
        room_after = float(base[k + 1]) - end if k + 1 < n else 0.0
        passes = 0
        for r in range(repeats, 0, -1):
            back_ok = here + r * shift <= end - shift
            # The last stitch ends short of the end instead of past it (the lock anchors there).
            ahead_ok = (k + 1 < n and r * shift + shift <= room_after) or \
                (k + 1 == n and here + r * shift <= end - 2 * shift)
            if back_ok and ahead_ok:
                passes = r
                break
        sign = 1.0 if k + 1 < n else -1.0
        for r in range(1, passes + 1):
            out.append(here + r * shift)
            out.append(end + sign * r * shift)
        here = out[-1]
    return np.asarray(out)


def triple_stitch(stroke: Stroke, options: TripleOptions = TripleOptions()) -> NeedlePoints:
    """Bean stitch along `stroke` (mm): forward, back, forward over every running stitch."""
    curve = dense_curve(stroke, DENSE_TOLERANCE)
    # Where the line retraces itself, base holes keep clear of the passes' holes beside the
    # holes of the way out (each pass pierces up to repeats x shift from its base hole).
    base = running_stitch(stroke, options.running, curve=curve,
                          fresh=FRESH_HOLE + options.repeats * options.shift)
    s_base = np.interp(base.t, curve.t, curve.s)
    s = bean_lengths(s_base, options.repeats, options.shift)
    t = curve.t_at(s)
    # Base holes keep their exact positions (corners); the shifted ones come from the curve.
    points = stroke.points_at(t)
    return NeedlePoints.of(points, t, BODY)
