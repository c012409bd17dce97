"""The ink outline (paper 3.1): sub-pixel contours of the gray image at the ink threshold."""

from __future__ import annotations

import numpy as np
from skimage.measure import find_contours

from vectorize.stroke import edge_lengths


def outline_rings(gray: np.ndarray, level: float, spacing: float) -> list[np.ndarray]:
    """Closed outline rings of the ink, resampled every `spacing` px: list of (N, 2) x, y arrays.

    The image is padded with paper so that ink touching the border still gives closed
    rings. Rings shorter than a few samples (isolated pixels) are dropped.
    """
    padded = np.pad(gray, 1, constant_values=1.0)
    rings = []
    for contour in find_contours(padded, level):
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
