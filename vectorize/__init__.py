"""Raster or SVG line drawings to ordered cubic Bézier strokes (`Drawing`)."""

from vectorize.drawing import Drawing
from vectorize.pipeline import (
    VectorizeOptions,
    VectorizeReport,
    VectorizeResult,
    vectorize_file,
    vectorize_image,
)
from vectorize.stroke import Stroke

__all__ = [
    "Stroke",
    "Drawing",
    "VectorizeOptions",
    "VectorizeReport",
    "VectorizeResult",
    "vectorize_file",
    "vectorize_image",
]
