"""`Drawing`: ordered strokes on a canvas; stroke order and direction are the drawing order."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from onestroke.errors import InputError
from vectorize.stroke import Stroke

UNITS = ("px", "mm")


@dataclass(frozen=True, eq=False)
class Drawing:
    """An ordered tuple of strokes on a `width` x `height` canvas in `unit` ("px" or "mm").

    `stroke_width` is the measured (or declared) ink width in the same unit.
    """

    strokes: tuple[Stroke, ...]
    width: float
    height: float
    unit: str = "px"
    stroke_width: float = 1.0
    meta: dict = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "strokes", tuple(self.strokes))
        if self.unit not in UNITS:
            raise InputError(f"drawing unit {self.unit!r} is not one of {UNITS}")
        if not (self.width > 0 and self.height > 0):
            raise InputError(f"drawing canvas {self.width} x {self.height} must be positive")

    @property
    def length(self) -> float:
        """Total length of all strokes."""
        return float(sum(s.length for s in self.strokes))

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) over all strokes; raises on an empty drawing."""
        if not self.strokes:
            raise InputError("the drawing has no strokes")
        b = np.array([s.bounds() for s in self.strokes])
        return float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()), float(b[:, 3].max())

    def with_strokes(self, strokes) -> "Drawing":
        """A copy holding other strokes (same canvas, unit and width)."""
        return replace(self, strokes=tuple(strokes))

    def transformed(self, matrix: np.ndarray, *, width: float, height: float, unit: str,
                    stroke_width: float) -> "Drawing":
        """Every stroke through the 2x3 affine `matrix`, on a new canvas."""
        return replace(self, strokes=tuple(s.transformed(matrix) for s in self.strokes),
                       width=width, height=height, unit=unit, stroke_width=stroke_width)
