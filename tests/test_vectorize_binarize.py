"""The ink mask: worked out on the ink's bounding box, it is the mask the whole image gives
(pieces, specks, a dark frame, filled holes, width), checked against scipy run on the
whole image."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from tests.conftest import figure_eight, render_polylines
from tests.test_vectorize_inputs import shaded_scan
from vectorize.raster.binarize import (
    blurred,
    downscaled_gray,
    estimate_stroke_width,
    extract_ink,
    frame_labels,
    grow,
    ink_depth,
    ink_image,
    ink_threshold,
    paper_gray,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _whole_image_ink(gray: np.ndarray, level: float) -> tuple[np.ndarray, float, bool]:
    """The kept ink by its definition, over the whole image: pieces 8-connected, a frame
    dropped, specks under a width squared dropped, 4-connected holes under half a width
    squared filled."""
    ink = gray < level
    labels, count = ndimage.label(ink, structure=np.ones((3, 3)))
    frame = frame_labels(labels, count)
    framed = 0 < frame.size < count
    if framed:
        ink &= ~np.isin(labels, frame)
    width = estimate_stroke_width(ink)
    sizes = ndimage.sum_labels(ink, labels, np.arange(1, count + 1))
    ink = np.isin(labels, np.flatnonzero(sizes >= max(4.0, width * width)) + 1)
    holes, count = ndimage.label(ndimage.binary_fill_holes(ink) & ~ink)
    sizes = ndimage.sum_labels(np.ones_like(ink), holes, np.arange(1, count + 1))
    return ink | np.isin(holes, np.flatnonzero(sizes < max(2.0, 0.5 * width * width)) + 1), width, framed


def _pages() -> list[tuple[str, np.ndarray]]:
    pages = [(path.name, np.asarray(Image.open(path))) for path in
             (EXAMPLES / "loops.png", EXAMPLES / "hershey-HersheySans1-ampersand.png")]
    sheet = shaded_scan(render_polylines([figure_eight()], width=4.0))
    photo = np.full((sheet.shape[0] + 120, sheet.shape[1] + 120), 45, dtype=np.uint8)  # a table around it
    photo[60:-60, 60:-60] = sheet
    pages.append(("framed photo", photo))
    # Ink at the image's edges, a blob with a pinhole and a pore, and specks in the corners.
    edge = render_polylines([figure_eight()], width=5.0)[:, 40:330].copy()
    edge[20:60, 120:160] = 0
    edge[30:32, 130:132] = 255
    edge[45:48, 145:147] = 255
    edge[0:2, -2:] = 0
    edge[-1, 0] = 0
    pages.append(("edges", edge))
    return pages


@pytest.mark.parametrize("name, page", _pages(), ids=[name for name, _ in _pages()])
def test_ink_of_the_box_is_the_ink_of_the_whole_image(name, page):
    gray, scale = paper_gray(page, max_size=1000, blur=0.0)
    for threshold in (None, 0.35, 0.6):
        level = ink_threshold(gray, threshold)
        expected, expected_width, expected_framed = _whole_image_ink(gray, level)
        # One thread, and the width measured in a second one while the pieces and the
        # paper are labelled (a frame or a dropped speck makes that paper labelling stale).
        for threads in (1, 2):
            ink, found, width, framed = extract_ink(gray, threshold=threshold, threads=threads)
            assert found == level
            assert np.array_equal(ink, expected), (name, threshold, threads)
            assert (width, framed) == (expected_width, expected_framed)
    assert framed == (name == "framed photo")
    if name == "edges":  # the pinholes in the blob were filled, the corner specks dropped
        assert (ink & (gray >= level)).sum() >= 4 and not ink[0, -1] and not ink[-1, 0]
    # The working image outside the box around the ink is paper; inside, ink is below the
    # threshold and everything else at or above it.
    work = ink_image(gray, scale, threshold=None)
    assert np.array_equal(work.gray < work.threshold, work.ink)
    near = ndimage.binary_dilation(work.ink, iterations=2)
    assert np.array_equal(work.gray[~near], np.ones(int((~near).sum()), dtype=np.float32))
    assert np.array_equal(work.gray[near & ~work.ink] >= work.threshold, np.ones(int((near & ~work.ink).sum()), bool))


def test_a_frame_is_found_in_a_crop_as_in_the_whole_image():
    page = np.ones((300, 400), dtype=bool)
    page[:, :] = False
    page[:40, :] = True  # a thick band along the top edge
    page[100:104, 100:300] = True  # a line inside
    labels, count = ndimage.label(page, structure=np.ones((3, 3)))
    whole = frame_labels(labels, count)
    # The crop keeps the top edge and adds one paper column and row on the other sides.
    crop = labels[:105, 99:301]
    assert whole.tolist() == frame_labels(crop, count, longest=400).tolist() == [1]
    # The band is a frame by the image's longest side, not by the crop's: in an image ten
    # times larger it would be too thin to be one.
    assert frame_labels(crop, count, longest=4000).tolist() == []


def _closing_flattened(gray: np.ndarray) -> np.ndarray:
    """`flatten_paper` by its definition: a grey closing, box-smoothed, divided out."""
    size = max(31, int(round(max(gray.shape) / 8)))
    paper = ndimage.grey_closing(gray, size=(size, size), mode="nearest")
    paper = ndimage.uniform_filter(paper.astype(np.float64), size=size, mode="nearest")
    return np.clip(gray / np.maximum(paper, 0.3), 0.0, 1.0).astype(np.float32)


@pytest.mark.parametrize("name, page", _pages(), ids=[name for name, _ in _pages()])
def test_flattened_paper_is_the_closing_divided_out(name, page):
    from vectorize.raster.binarize import flatten_paper, working_gray

    for blur in (0.0, 1.5):
        gray, _ = working_gray(page, max_size=1000, blur=blur)
        assert np.array_equal(flatten_paper(gray), _closing_flattened(gray)), (name, blur)


def test_a_window_holds_the_mask_where_the_maximum_filter_says_so():
    from vectorize.raster.binarize import in_every_window

    rng = np.random.default_rng(5)
    found = 0
    for _ in range(300):
        h, w = rng.integers(16, 260, 2)
        size = int(rng.integers(3, 130))
        mask = rng.random((h, w)) < rng.choice([0.0005, 0.002, 0.01, 0.05])
        if in_every_window(mask, size):  # never claimed where a window of either origin misses
            found += 1
            assert ndimage.maximum_filter(mask, size=size, mode="nearest").all()
            assert ndimage.grey_dilation(mask.astype(np.uint8), size=(size, size), mode="nearest").all()
    assert found > 50
    # A clean page holds its paper level everywhere; one dark band wider than a window does not.
    gray, _ = paper_gray(_pages()[0][1], max_size=1000, blur=0.0)
    assert in_every_window(gray == gray.max(), 125)
    gray[:, 300:500] = 0.2
    assert not in_every_window(gray == gray.max(), 125)


def test_the_paper_noise_floor_of_clean_paper_is_its_level():
    from vectorize.raster.binarize import paper_noise_floor

    def by_percentiles(gray):
        q25, median = np.percentile(gray, [25, 50])
        sigma = (median - q25) / 0.6745
        return None if sigma > 0.1 else float(median - 4.5 * sigma)

    rng = np.random.default_rng(2)
    for n in (17, 400, 1001, 4096):
        # Around the share of the brightest level where the lower quartile reaches it.
        edge = int(0.25 * (n - 1))
        for dark in (edge - 1, edge, edge + 1, edge + 2, n // 2):
            gray = np.full(n, np.float32(0.97))
            gray[:dark] = rng.random(dark).astype(np.float32) * 0.97
            rng.shuffle(gray)
            assert paper_noise_floor(gray.reshape(1, -1)) == by_percentiles(gray), (n, dark)
    page = paper_gray(_pages()[1][1], max_size=1000, blur=0.0)[0]
    assert paper_noise_floor(page) == by_percentiles(page) == float(page.max())


def _scipy_width(ink: np.ndarray) -> float:
    """The stroke width by its definition: the distance transform and the 3 x 3 maximum
    filter of scipy over the whole image."""
    distance = ndimage.distance_transform_edt(ink)
    values = distance[(distance >= ndimage.maximum_filter(distance, size=3) - 1e-6) & ink]
    return 1.0 if values.size == 0 else float(max(1.0, 2.0 * np.median(values) - 0.5))


@pytest.mark.parametrize("name, page", _pages(), ids=[name for name, _ in _pages()])
def test_ink_depth_and_width_are_scipys(name, page):
    gray, _ = paper_gray(page, max_size=1000, blur=0.0)
    for level in (0.3, 0.5, 0.8):
        ink = gray < level
        assert np.array_equal(ink_depth(ink), ndimage.distance_transform_edt(ink)), (name, level)
        assert estimate_stroke_width(ink) == _scipy_width(ink), (name, level)


def test_ink_depth_on_small_masks_at_the_edges():
    # Ink on the image's edges, all ink, no ink, one pixel, thin and wide shapes.
    rng = np.random.default_rng(3)
    masks = [np.ones((5, 7), bool), np.zeros((4, 4), bool), np.eye(6, dtype=bool), np.ones((1, 9), bool)]
    masks += [rng.random((rng.integers(1, 25), rng.integers(1, 25))) < rng.random() for _ in range(200)]
    for mask in masks:
        assert np.array_equal(ink_depth(mask), ndimage.distance_transform_edt(mask))
        if mask.any():
            assert estimate_stroke_width(mask) == _scipy_width(mask)


@pytest.mark.parametrize("name, page", _pages(), ids=[name for name, _ in _pages()])
def test_the_blur_of_the_box_is_skimages_blur_of_the_whole_image(name, page):
    from skimage.filters import gaussian

    gray, _ = downscaled_gray(page, max_size=1000)
    spotted = gray.copy()
    spotted[0, -1] = spotted[-1, 0] = 0.5  # a dark pixel in two corners: the box is the image
    for image in (gray, spotted):
        for blur in (0.3, 1.0, 2.5):
            expected = gaussian(image, sigma=blur, preserve_range=True).astype(np.float32)
            for threads in (1, 2):  # the box whole, or its two halves side by side
                assert np.array_equal(blurred(image, blur, threads=threads), expected), (name, blur, threads)
    assert blurred(gray, 0.0) is gray


def test_grow_is_scipys_binary_dilation():
    rng = np.random.default_rng(5)
    masks = [np.zeros((3, 4), bool), np.ones((1, 6), bool), np.eye(7, dtype=bool)[::-1]]
    masks += [rng.random((rng.integers(1, 30), rng.integers(1, 30))) < rng.random() * 0.3 for _ in range(100)]
    for mask in masks:
        for steps in (1, 2, 3):
            assert np.array_equal(grow(mask, steps), ndimage.binary_dilation(mask, iterations=steps))
            assert np.array_equal(grow(mask, steps, square=True),
                                  ndimage.binary_dilation(mask, structure=np.ones((3, 3)), iterations=steps))


def test_a_phone_photo_becomes_gray_row_block_by_row_block():
    # a 4000 x 3000 colour photo: the gray image is 48 MB; converting all channels to float
    # at once took two 144 MB copies on the way (a 3500 px photo peaked over 600 MB)
    import tracemalloc

    from vectorize.raster.binarize import GRAY_ROWS, _to_gray, to_gray

    rng = np.random.default_rng(0)
    small = (rng.random((GRAY_ROWS * 2 + 17, 50, 3)) * 255).astype(np.uint8)
    assert np.array_equal(to_gray(small), _to_gray(small))  # same values as all at once
    rgba = (rng.random((GRAY_ROWS + 3, 40, 4)) * 65535).astype(np.uint16)
    assert np.array_equal(to_gray(rgba), _to_gray(rgba))
    photo = np.full((3000, 4000, 3), 200, dtype=np.uint8)
    tracemalloc.start()
    try:
        gray = to_gray(photo)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert gray.shape == (3000, 4000) and gray.dtype == np.float32
    assert peak < 48e6 + 30e6  # the result and a row block's float copies (was 288 MB)
