"""The ink outline (paper 3.1): sub-pixel contours of the gray image at the ink threshold."""

from __future__ import annotations

import numpy as np
from skimage.measure import find_contours

from vectorize.stroke import edge_lengths


def padded_contours(gray: np.ndarray, level: float) -> list[np.ndarray]:
    """`skimage.measure.find_contours` of `gray` (H, W) padded with a row and a column of
    paper (1.0) on every side, at `level`: the same (K, 2) row, column arrays in the padded
    image's frame, in the same order, from less of the image.

    Marching squares finds a contour only in squares with a corner at or below the level:
    the rows and columns past the last such pixel, and one more, are left out (their squares
    have none, and the squares before them come in the same order). The first rows and
    columns stay: a contour point is its square's row or column plus a fraction, and the same
    sum from a cropped row number would round differently.
    """
    dark = gray <= level
    rows, cols = np.flatnonzero(dark.any(axis=1)), np.flatnonzero(dark.any(axis=0))
    if not rows.size:
        return []
    bottom, right = int(rows[-1]) + 2, int(cols[-1]) + 2  # padded rows and columns kept: 0 .. bottom
    padded = np.ones((bottom + 1, right + 1), dtype=gray.dtype)
    part = gray[:bottom, :right]
    padded[1:1 + part.shape[0], 1:1 + part.shape[1]] = part
    return find_contours(padded, level)


def outline_rings(gray: np.ndarray, level: float, spacing: float) -> list[np.ndarray]:
    """Closed outline rings of the ink, resampled every `spacing` px: list of (N, 2) x, y arrays.

    The image is padded with paper so that ink touching the border still gives closed
    rings. Rings shorter than a few samples (isolated pixels) are dropped.
    """
    rings = []
    for contour in padded_contours(gray, level):
        xy = contour[:, ::-1] - 1.0  # (row, col) -> (x, y), undo the padding
        if len(xy) < 4:
            continue
        if np.linalg.norm(xy[0] - xy[-1]) > 1e-6:
            xy = np.vstack([xy, xy[:1]])
        steps = edge_lengths(xy)
        length = float(steps.sum())
        count = int(np.ceil(length / spacing))
        if count < 6:
            continue
        arc = np.concatenate([[0.0], np.cumsum(steps)])
        at = np.linspace(0.0, length, count, endpoint=False)
        rings.append(np.column_stack([np.interp(at, arc, xy[:, 0]), np.interp(at, arc, xy[:, 1])]))
    return rings
