"""Anti-aliased rendering of a `Drawing` for the benchmark: gray float in [0, 1], 1 = paper.

A distance field: every pixel near the ink gets the exact distance d from its centre to the
nearest centre line (strokes sampled every 0.2 px, nearest sample by a k-d tree; the chord
error is below 0.01 px), and its ink coverage is clip(w/2 - d + 1/2, 0, 1), the area a
straight edge covers in a unit pixel. This gives round caps and joins for free and, unlike a
polygon rasterizer, does not depend on how finely the curve was cut into segments, so the
ground truth and an output that follows the same curve render to the same pixels.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from vectorize.drawing import Drawing

SAMPLE_SPACING = 0.2  # px along the centre line


def render(drawing: Drawing, *, stroke_width: float | None = None, size: tuple[int, int] | None = None) -> np.ndarray:
    """Render `drawing` (px) on its canvas: (H, W) float64 in [0, 1], 1 = paper, 0 = full ink.

    stroke_width: ink width in px (default: the drawing's own); size: (W, H) canvas in px
    (default: the drawing's width and height, rounded). Pixel (row r, column c) covers
    x in [c, c + 1), y in [r, r + 1).
    """
    if size is None:
        size = (int(round(drawing.width)), int(round(drawing.height)))
    width, height = size
    w = float(drawing.stroke_width if stroke_width is None else stroke_width)
    image = np.ones((height, width), dtype=np.float64)
    if not drawing.strokes:
        return image
    samples = np.concatenate([s.sample_evenly(SAMPLE_SPACING) for s in drawing.strokes])
    # pixels that can receive ink: within w/2 + 1.5 px of a sample's pixel
    cols = np.floor(samples[:, 0]).astype(int)
    rows = np.floor(samples[:, 1]).astype(int)
    inside = (cols >= -1) & (cols <= width) & (rows >= -1) & (rows <= height)
    seed = np.zeros((height + 2, width + 2), dtype=bool)
    seed[rows[inside] + 1, cols[inside] + 1] = True
    if not seed.any():
        return image
    reach = w / 2 + 1.5
    band = ndimage.distance_transform_edt(~seed) <= reach
    band = band[1:-1, 1:-1]
    r, c = np.nonzero(band)
    centres = np.c_[c + 0.5, r + 0.5]
    d, _ = cKDTree(samples).query(centres, distance_upper_bound=reach + 1.0)
    coverage = np.clip(w / 2 - d + 0.5, 0.0, 1.0)
    image[r, c] = 1.0 - coverage
    return image


def to_uint8(gray: np.ndarray) -> np.ndarray:
    """Gray float in [0, 1] to uint8 (what a PNG holds and what the vectorizer is given)."""
    return np.clip(np.round(gray * 255.0), 0, 255).astype(np.uint8)
