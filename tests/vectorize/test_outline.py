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


def _bar_and_ring(width: float) -> np.ndarray:
    """Gray page (1 = paper) with a straight bar and a ring of ink (radius 15 px), each `width` px wide."""
    yy, xx = np.mgrid[0:200, 0:300].astype(float)
    bar = np.maximum.reduce([np.abs(yy - 50.3) - width / 2, 20 - xx, xx - 280])
    ring = np.abs(np.hypot(xx - 150, yy - 140) - 15) - width / 2
    return np.clip(np.minimum(bar, ring) + 0.5, 0.0, 1.0)


def test_straight_outline_is_sampled_sparsely_and_curves_densely():
    """Along the bar's straight sides samples are ~`sparse` apart; around the ring and the
    bar's ends `spacing` apart as without `sparse`; every sample lies on the contour."""
    import shapely
    from shapely import LinearRing

    from vectorize.raster.outline import outline_rings

    gray = _bar_and_ring(8.0)
    dense = outline_rings(gray, 0.5, 1.0)
    sparse = outline_rings(gray, 0.5, 1.0, sparse=4.0)
    assert len(dense) == len(sparse) == 3  # the bar, the ring's outside and inside
    steps = [np.sort(np.hypot(*np.diff(np.vstack([r, r[:1]]), axis=0).T)) for r in sparse]
    bar = max(range(3), key=lambda k: np.ptp(sparse[k][:, 0]) / max(np.ptp(sparse[k][:, 1]), 1))
    # The bar (~260 x 8 px): its two long sides at ~4 px, its ends at ~1 px.
    assert len(dense[bar]) > 520
    assert abs(len(sparse[bar]) - (2 * 260 / 4 + 2 * 8)) <= 6
    assert np.median(steps[bar]) == pytest.approx(4.0, abs=0.2)
    assert steps[bar][:10].max() < 1.2
    for k in range(3):
        if k != bar:  # the ring's circles are curved everywhere: as dense as before
            assert abs(len(sparse[k]) - len(dense[k])) <= 2
            assert steps[k].max() < 1.1
    for ring, contour in zip(sparse, dense):
        # (The dense ring's chords cut the contour's corners by up to ~0.25 px.)
        assert shapely.distance(LinearRing(contour), shapely.points(ring)).max() < 0.3
