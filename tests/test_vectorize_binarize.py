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
from vectorize.binarize import (
    estimate_stroke_width,
    extract_ink,
    frame_labels,
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
        ink, found, width, framed = extract_ink(gray, threshold=threshold)
        expected, expected_width, expected_framed = _whole_image_ink(gray, level)
        assert found == level
        assert np.array_equal(ink, expected), (name, threshold)
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
