"""The numpy PEC thumbnail draws exactly the pixels pyembroidery's own loop draws."""

from __future__ import annotations

import io

import numpy as np
import pyembroidery
import pytest
from pyembroidery import PecGraphics, PecWriter

from benchmarks.sets.embroidery_designs import STYLE_NAMES, design
from fabrication.embroidery.export import embroidery_bytes, to_pattern
from fabrication.embroidery.pec_thumbnail import fast_pec_thumbnails, numpy_draw_scaled
from fabrication.embroidery.plan import PlanOptions, plan_embroidery, style_options
from machines.hoops import format_for_path


def both(extends, points, stride=6, buffer=5):
    ours, theirs = PecGraphics.get_blank(), PecGraphics.get_blank()
    numpy_draw_scaled(extends, points, ours, stride, buffer)
    PecGraphics.draw_scaled(extends, points, theirs, stride, buffer)
    return ours, theirs


@pytest.mark.parametrize("seed", range(6))
def test_same_pixels_as_pyembroidery_on_random_stitches(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3000))
    points = [[int(x), int(y), pyembroidery.STITCH] for x, y in rng.integers(-900, 1400, size=(n, 2))]
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    fitted = (min(xs), min(ys), max(xs), max(ys))
    ours, theirs = both(fitted, points, buffer=int(rng.integers(0, 6)))
    assert ours == theirs
    assert any(ours)
    # Extents smaller than the points push pixels off the icon, past its end and to negative
    # indices that Python wraps: the quirks come out the same too.
    ours, theirs = both((-100, -50, 100, 80), points)
    assert ours == theirs


def test_degenerate_inputs_match():
    one = [[5, 7, pyembroidery.STITCH]]
    assert both((5, 7, 5, 7), one)[0] == both((5, 7, 5, 7), one)[1]  # zero-size design
    assert both((0, 0, 10, 10), [])[0] == PecGraphics.get_blank()
    ragged = [[1, 2], [3, 4, 0]]  # not rows of equal length: the library's loop takes over
    ours, theirs = both((0, 0, 10, 10), ragged)
    assert ours == theirs and any(ours)


@pytest.mark.parametrize("version", [1, 6])
@pytest.mark.parametrize("style", STYLE_NAMES)
def test_pes_bytes_identical_to_pyembroidery_alone(style, version):
    plan = plan_embroidery(design(), PlanOptions(style=style_options(style)))
    fmt = format_for_path("x.pes")
    buffer = io.BytesIO()
    pyembroidery.write_pes(to_pattern(plan, fmt), buffer, {**fmt.settings, "encode": False,
                                                           "pes version": version})
    assert embroidery_bytes(plan, fmt, pes_version=version) == buffer.getvalue()


def test_swap_is_undone_even_on_error():
    original = PecWriter.draw_scaled
    with pytest.raises(RuntimeError):
        with fast_pec_thumbnails():
            assert PecWriter.draw_scaled is numpy_draw_scaled
            raise RuntimeError("writer failed")
    assert PecWriter.draw_scaled is original


def test_without_the_library_function_nothing_is_swapped(monkeypatch):
    import fabrication.embroidery.pec_thumbnail as thumbnail

    monkeypatch.setattr(thumbnail, "_original_draw_scaled", None)
    before = PecWriter.draw_scaled
    with fast_pec_thumbnails():
        assert PecWriter.draw_scaled is before
    plan = plan_embroidery(design(), PlanOptions(style=style_options("running")))
    assert embroidery_bytes(plan, format_for_path("x.pes"))[:8] == b"#PES0060"
