"""Junction crops: shape, invariants and the window/whole-image equivalence."""

from __future__ import annotations

import numpy as np
import pytest

from onestroke.errors import InputError
from vectorize.junctions.junction_crop import CropSpec, crop_junctions, dihedral_copies


def _cross_image(size=400, width=5.0):
    """Two anti-aliased strokes crossing at pixel (row 210, column 200), and a distant third."""
    yy, xx = np.mgrid[0:size, 0:size].astype(float)  # pixel centres at integer (x, y)
    d1 = np.abs((xx - 200) * np.sin(0.3) - (yy - 210) * np.cos(0.3))
    d2 = np.abs((xx - 200) * np.sin(1.4) - (yy - 210) * np.cos(1.4))
    d3 = np.abs(yy - 40)
    ink = np.clip(width / 2 - np.minimum(np.minimum(d1, d2), d3) + 0.5, 0, 1)
    return (1.0 - 0.9 * ink).astype(np.float32)


def test_shape_range_and_empty():
    gray = _cross_image()
    crops = crop_junctions(gray, np.array([[200.0, 210.0], [120.0, 300.0]]), 5.0)
    assert crops.shape == (2, 2, 48, 48) and crops.dtype == np.float32
    assert crops.min() >= 0.0 and crops.max() <= 1.0
    assert crops[0, 0].max() == pytest.approx(1.0)  # the junction's ink is the darkest
    assert crop_junctions(gray, np.zeros((0, 2)), 5.0).shape == (0, 2, 48, 48)


def test_one_at_a_time_equals_all_at_once():
    # Few junctions filter windows, many filter the whole image: the values must agree.
    gray = _cross_image()
    rng = np.random.default_rng(0)
    centers = rng.uniform(150, 250, (40, 2))
    together = crop_junctions(gray, centers, 4.0)
    alone = np.concatenate([crop_junctions(gray, c[None], 4.0) for c in centers[:5]])
    assert np.allclose(together[:5], alone, atol=1e-6)


def test_crop_follows_the_ink_not_the_image_axes():
    # Rotating the image by 90 degrees rotates the crop frame with it: the crop comes out
    # the same. (399 px: a multiple of the block-reduction factor 3 used at this width, so
    # the block grid also maps onto itself.)
    gray = _cross_image(size=399)
    a = crop_junctions(gray, np.array([[200.0, 210.0]]), 5.0)
    rotated = np.ascontiguousarray(np.rot90(gray))  # (x, y) -> (y, W - 1 - x)
    b = crop_junctions(rotated, np.array([[210.0, 398.0 - 200.0]]), 5.0)
    assert np.allclose(a, b, atol=1e-5)


def test_outside_the_image_is_paper():
    gray = _cross_image()
    crops = crop_junctions(gray, np.array([[-5000.0, -5000.0]]), 5.0)
    assert np.all(crops == 0.0)


@pytest.mark.parametrize("width", [0.0, -1.0, float("nan")])
def test_bad_stroke_width_is_refused(width):
    with pytest.raises(InputError):
        crop_junctions(_cross_image(), np.array([[200.0, 200.0]]), width)


def test_dihedral_copies_are_the_eight_symmetries():
    x = np.random.default_rng(1).random((3, 2, 6, 6)).astype(np.float32)
    copies = dihedral_copies(x)
    assert copies.shape == (8, 3, 2, 6, 6)
    flat = {c.tobytes() for c in copies}
    assert len(flat) == 8
    assert np.array_equal(copies[0], x)
    assert CropSpec().to_dict()["size"] == 48
