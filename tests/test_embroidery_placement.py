"""Where the design lands in the hoop (issue 27): --fit turns a design a quarter when that
fits without scaling, and says so; the stitches (not the curve) are centred on the hoop."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.embroidery_designs import STYLE_NAMES, design
from fabrication.embroidery.hooping import hoop_design
from fabrication.embroidery.pipeline import EmbroideryJob, embroider
from fabrication.embroidery.plan import PlanOptions, style_options
from fabrication.placement import PlacementOptions, place
from machines.hoops import hoop_named
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _landscape() -> Drawing:
    """A wave 150 mm wide and about 60 mm tall (y down)."""
    x = np.linspace(0.0, 150.0, 200)
    return Drawing((Stroke.from_polyline(np.c_[x, 30.0 + 30.0 * np.sin(x / 15.0)]),), 150, 60, "mm")


def test_a_landscape_design_is_refused_by_a_portrait_hoop_with_the_turn_offered():
    job = EmbroideryJob(placement=PlacementOptions(size=150.0), hoop=hoop_named("130x180"))
    with pytest.raises(InputError, match=r"turned by 90 degrees it fits: add --fit \(or --rotate 90\)"):
        embroider(_landscape(), job)


def test_fit_turns_a_quarter_when_that_fits_without_scaling_and_says_so():
    hoop = hoop_named("130x180")
    result = embroider(_landscape(), EmbroideryJob(placement=PlacementOptions(size=150.0), hoop=hoop, fit=True))
    assert result.turned and result.fit_scale == 1.0
    assert any(w.startswith("turned by 90 degrees") and "130x180" in w for w in result.warnings), result.warnings
    x0, y0, x1, y1 = result.plan.bounds()
    assert hoop.contains((x0, y0, x1, y1))
    assert y1 - y0 == pytest.approx(150.0, abs=0.3) and x1 - x0 < 65.0  # full size, standing up
    # The same turn as --rotate 90 (counter-clockwise on screen, y down): the wave's start,
    # on the left, ends up at the bottom.
    rotated = embroider(_landscape(), EmbroideryJob(placement=PlacementOptions(size=150.0, rotate=90.0),
                                                    hoop=hoop))
    assert np.array_equal(rotated.plan.points, result.plan.points)
    first = result.plan.points[result.plan.kinds == 0][0]
    assert first[1] > 70.0


def test_fit_still_scales_when_no_turn_fits():
    big = place(_landscape(), PlacementOptions(size=160.0))
    fitted = hoop_design(big, hoop_named("100x100"), fit=True)
    assert not fitted.turned and fitted.scale < 0.65
    assert hoop_design(big, hoop_named("200x200")).drawing is big


@pytest.mark.parametrize("style", STYLE_NAMES)
def test_the_stitches_bounding_box_is_centred_on_the_hoop(style):
    """The curve's box is centred by placement; a zigzag or arrows reach further on one
    side of the curve, so the stitches are centred on their own box (to half a grid step)."""
    result = embroider(design(), EmbroideryJob(placement=PlacementOptions(size=80.0),
                                              plan=PlanOptions(style=style_options(style))))
    x0, y0, x1, y1 = result.plan.bounds()
    assert abs(x0 + x1) / 2 <= 0.05 + 1e-9 and abs(y0 + y1) / 2 <= 0.05 + 1e-9
    # The strokes as sewn moved with the stitches: the needle points still lie on them.
    plan = result.plan
    rows = np.flatnonzero((plan.kinds == 0) & (plan.roles == 0))
    if style in ("running", "triple"):
        k = plan.strokes[rows]
        on = np.array([result.drawing.strokes[s].points_at(t - s) for s, t in zip(k, plan.params[rows])])
        assert np.abs(on - plan.points[rows]).max() <= 0.08
