"""The outline's marching squares run over part of the page (`outline.padded_contours`): the
contours must be skimage's over the whole padded page, bit for bit and in the same order
(the Voronoi diagram, and so the SVG, hangs on every coordinate)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage
from skimage.measure import find_contours

from vectorize.raster.binarize import ink_image, paper_gray
from vectorize.raster.image_io import load_image
from vectorize.raster.outline import padded_contours

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "examples").glob("*.png"))


def _whole_page(gray: np.ndarray, level: float) -> list[np.ndarray]:
    return find_contours(np.pad(gray, 1, constant_values=1.0), level)


def _same(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))


@pytest.mark.parametrize("path", EXAMPLES[:4], ids=lambda p: p.stem)
def test_contours_of_drawings_are_skimages_over_the_whole_page(path):
    image, _ = load_image(path, max_size=1000)
    gray, scale = paper_gray(image, max_size=1000, blur=0.0)
    ink = ink_image(gray, scale, threshold=None)
    assert _same(padded_contours(ink.gray, ink.threshold), _whole_page(ink.gray, ink.threshold))
    # Ink running off the bottom and right edges (the crop reaches the padding there) and
    # off the top and left.
    for rows, cols in ((slice(-3, None), slice(None)), (slice(None), slice(-2, None)),
                       (slice(0, 2), slice(None)), (slice(None), slice(0, 1))):
        edged = ink.gray.copy()
        edged[rows, cols] = 0.0
        assert _same(padded_contours(edged, ink.threshold), _whole_page(edged, ink.threshold))


def test_contours_of_random_blobs_and_exact_levels():
    rng = np.random.default_rng(7)
    for _ in range(60):
        h, w = rng.integers(4, 60, 2)
        blobs = ndimage.gaussian_filter(rng.random((h, w)), 1.5)
        gray = np.clip(1.0 - (blobs > np.quantile(blobs, rng.uniform(0.6, 0.98))) * rng.uniform(0.3, 1.0), 0, 1)
        gray = gray.astype(np.float32)
        level = float(gray[gray < 1].min()) if (gray < 1).any() and rng.random() < 0.3 else 0.5  # a pixel at the level
        assert _same(padded_contours(gray, level), _whole_page(gray, level))
    assert padded_contours(np.ones((5, 5), np.float32), 0.5) == []
