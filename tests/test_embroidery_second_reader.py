"""Every style in every format read by two readers: pyembroidery and our own decoder of
the formats' layouts (tests/embroidery_reader.py, no code shared with pyembroidery). Both
must see the planned needle points exactly, and the same colour changes and trims."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from benchmarks.sets.embroidery_designs import FORMATS, STYLE_NAMES, design
from embroidery_reader import COLOR, TRIM, read_stitches
from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.plan import COLOR as PLAN_COLOR, STITCH, TRIM as PLAN_TRIM
from fabrication.embroidery.plan import PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.read import read_embroidery
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _three_colours() -> Drawing:
    """Three threads, red twice and far apart: two colour changes, trims within a colour."""
    red, green, blue = (200, 30, 40), (20, 120, 40), (0, 0, 128)
    lines = [([-30, -30], [20, -25], red), ([-30, 0], [20, 5], green), ([-30, 30], [20, 25], blue),
             ([30, -30], [35, 30], red)]
    return Drawing(tuple(Stroke(Stroke.from_polyline(np.array([a, b], dtype=float)).control, c)
                         for a, b, c in lines), 80, 80, "mm")


DRAWINGS = {"design": design, "three colours": _three_colours}


@lru_cache(maxsize=None)
def _plan(drawing: str, style: str):
    return plan_embroidery(DRAWINGS[drawing](), PlanOptions(style=style_options(style)))


@pytest.mark.parametrize("ext", FORMATS)
@pytest.mark.parametrize("style", STYLE_NAMES + ("satin",))
@pytest.mark.parametrize("drawing", list(DRAWINGS))
def test_two_readers_see_the_planned_stitches(drawing, style, ext, tmp_path):
    plan = _plan(drawing, style)
    path = tmp_path / f"d.{ext}"
    write_embroidery(plan, path)
    ours = read_stitches(path)
    back = read_embroidery(path)
    planned = np.rint(plan.points[plan.kinds == STITCH] * 10).astype(np.int64)
    theirs = np.rint(back.plan.points[back.plan.kinds == STITCH] * 10).astype(np.int64)
    assert np.array_equal(ours.needles, planned)
    assert np.array_equal(theirs, planned)
    changes = int((plan.kinds == PLAN_COLOR).sum())
    assert ours.count(COLOR) == back.color_changes == changes
    trims = int((plan.kinds == PLAN_TRIM).sum())
    if ext in ("pes", "jef", "exp"):  # explicit trim records (DST trims by jumps; VP3 adds a last one)
        assert ours.count(TRIM) == trims
    if ext == "vp3":
        assert ours.count(TRIM) == trims + 1
