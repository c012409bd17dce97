"""The ink outline (paper 3.1): sub-pixel contours of the gray image at the ink threshold."""

from __future__ import annotations

import numpy as np
import shapely
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


# Straight stretches of the outline: the contour simplified within this many px (Douglas-
# Peucker, shapely's `simplify`); its edges of at least STRAIGHT_EDGES sparse steps are
# sampled every sparse step, the others (curves, ends) every `spacing` as everywhere before.
STRAIGHT_TOLERANCE = 0.15
STRAIGHT_EDGES = 2


def _sample_places(xy: np.ndarray, arc: np.ndarray, spacing: float, sparse: float) -> np.ndarray:
    """Arc lengths (N,) of the samples of the closed contour `xy` (K, 2, first point repeated
    last, `arc` its (K,) arc lengths): every ~`sparse` px along its straight edges, every
    ~`spacing` px elsewhere, each edge divided evenly from its first corner."""
    line = shapely.simplify(shapely.linestrings(xy), STRAIGHT_TOLERANCE, preserve_topology=False)
    corners = shapely.get_coordinates(line)
    # Douglas-Peucker keeps points of xy, in order: find them by their coordinates.
    key, corner_key = xy[:, 0] + 1j * xy[:, 1], corners[:, 0] + 1j * corners[:, 1]
    at = np.unique(arc[np.isin(key, corner_key)])
    at = np.union1d(at, [0.0, arc[-1]])
    chord = edge_lengths(np.column_stack([np.interp(at, arc, xy[:, 0]), np.interp(at, arc, xy[:, 1])]))
    straight = chord >= STRAIGHT_EDGES * sparse
    # Runs of curved edges are sampled as one stretch (short edges would each round up).
    cut = np.concatenate([[True], straight[1:] | straight[:-1], [True]])
    at = at[cut]
    length = np.diff(at)
    step = np.where(straight[cut[:-1]], sparse, spacing)
    count = np.maximum(np.round(length / step), 1).astype(np.int64)
    first = np.repeat(at[:-1], count)
    within = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    return first + within * np.repeat(length / count, count)


def outline_rings(gray: np.ndarray, level: float, spacing: float, sparse: float | None = None) -> list[np.ndarray]:
    """Closed outline rings of the ink, resampled every `spacing` px: list of (N, 2) x, y arrays.

    With `sparse` (px, > spacing), straight stretches are sampled only every ~`sparse` px
    (`_sample_places`): the Voronoi diagram of the samples, and so the medial axis, costs
    less, and its axis between two straight sides stays within sparse**2 / (8 w) px of
    the middle (w: the stroke width). The image is padded with paper so that ink touching
    the border still gives closed rings. Rings shorter than a few samples (isolated pixels) are dropped.
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
        if sparse is not None and sparse > spacing:
            at = _sample_places(xy, arc, spacing, sparse)
        else:
            at = np.linspace(0.0, length, count, endpoint=False)
        rings.append(np.column_stack([np.interp(at, arc, xy[:, 0]), np.interp(at, arc, xy[:, 1])]))
    return rings
