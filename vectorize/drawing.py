"""`Drawing`: ordered strokes on a canvas; stroke order and direction are the drawing order."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from onestroke.errors import InputError
from vectorize.stroke import Stroke, curve_bounds, scaled_widths

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
        return curve_bounds(np.concatenate([s.control for s in self.strokes]))

    def with_strokes(self, strokes) -> "Drawing":
        """A copy holding other strokes (same canvas, unit and width)."""
        return replace(self, strokes=tuple(strokes))

    def transformed(self, matrix: np.ndarray, *, width: float, height: float, unit: str,
                    stroke_width: float) -> "Drawing":
        """Every stroke through the 2x3 affine `matrix`, on a new canvas."""
        strokes = ()
        if self.strokes:
            # All strokes in one array pass (the same arithmetic as Stroke.transformed):
            # a drawing of 20,000 strokes would otherwise pay numpy's overhead 20,000 times.
            (a, b, tx), (c, d, ty) = np.asarray(matrix, dtype=float)
            control = np.concatenate([s.control for s in self.strokes])
            x, y = control[..., 0], control[..., 1]
            moved = np.stack([a * x + b * y + tx, c * x + d * y + ty], axis=-1)
            ends = np.cumsum([len(s.control) for s in self.strokes])[:-1]
            strokes = tuple(Stroke(piece, s.color, scaled_widths(s.widths, matrix))
                            for piece, s in zip(np.split(moved, ends), self.strokes))
        return replace(self, strokes=strokes, width=width, height=height, unit=unit, stroke_width=stroke_width)
