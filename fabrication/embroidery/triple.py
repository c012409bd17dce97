"""Triple (bean) stitch: each running stitch is sewn forward, back and forward again.

`repeats` back-and-forth passes per stitch: 1 repeat = 3 layers of thread, the bold
"backstitch" look of the paper's Fig. 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.needles import NeedlePoints
from fabrication.embroidery.running import RunningOptions, running_stitch
from onestroke.errors import InputError
from vectorize.stroke import Stroke


@dataclass(frozen=True, kw_only=True)
class TripleOptions:
    """Running-stitch placement (mm, degrees) plus `repeats` back-and-forth passes."""

    stitch_length: float = 2.5
    tolerance: float = 0.2
    corner_angle: float = 45.0
    repeats: int = 1

    def __post_init__(self) -> None:
        if not (isinstance(self.repeats, int) and 1 <= self.repeats <= 5):
            raise InputError(f"triple-stitch repeats {self.repeats!r} must be an integer from 1 to 5")
        self.running  # validates the running-stitch part

    @property
    def running(self) -> RunningOptions:
        return RunningOptions(stitch_length=self.stitch_length, tolerance=self.tolerance,
                              corner_angle=self.corner_angle)


def triple_stitch(stroke: Stroke, options: TripleOptions = TripleOptions()) -> NeedlePoints:
    """Bean stitch along `stroke` (mm): 0, 1, 0, 1, 2, 1, 2, ... for one repeat."""
    base = running_stitch(stroke, options.running)
    n = len(base)
    # After reaching point i, go back to i - 1 and forward to i, `repeats` times.
    pattern = np.array([0] + [-1, 0] * options.repeats)
    index = (np.arange(1, n)[:, None] + pattern[None, :]).ravel()
    return base.take(np.concatenate([[0], index]))
