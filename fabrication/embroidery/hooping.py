"""Hoop checks: a placed design must lie inside the hoop's sewing field, or be turned or
scaled to fit; and the stitches are centred in it.

The stitches stray from the curve by the style's reach (half a zigzag's width, half an
arrow's spread), so the check before stitching adds that reach; the final word is the
check of the stitch plan itself, on the needle points that will be written, after they
are centred on their own bounding box (`plan_embroidery(..., centre=True)`: a zigzag or
arrows reach further on one side of the curve than on the other).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.plan import StitchPlan
from machines.hoops import Hoop
from onestroke.errors import InputError
from vectorize.drawing import Drawing

# Room kept free at the hoop's edge when scaling to fit, mm: the grid snap and the
# stitch geometry can move needle points a little beyond the curve plus its reach.
FIT_MARGIN = 0.5
# A quarter turn counter-clockwise on screen (y down), the same as `--rotate 90`.
QUARTER_TURN = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


@dataclass(frozen=True, eq=False)
class Hooped:
    """A design made to fit: drawing (mm, centred), scale (1.0: as placed), turned (True:
    a quarter turn counter-clockwise, as `--rotate 90`, made it fit without scaling)."""

    drawing: Drawing
    scale: float = 1.0
    turned: bool = False


def _too_big(width: float, height: float, hoop: Hoop, turn_fits: bool = False) -> str:
    turn = ("; turned by 90 degrees it fits: add --fit (or --rotate 90)" if turn_fits else
            "; choose a smaller --size, a larger --hoop, or --fit")
    return (f"the design needs {width:.1f} x {height:.1f} mm but hoop {hoop.label} holds "
            f"{hoop.width:g} x {hoop.height:g} mm{turn}")


def hoop_design(drawing: Drawing, hoop: Hoop, *, reach: float = 0.0, fit: bool = False) -> Hooped:
    """`drawing` (mm, centred on (0, 0)) as it fits `hoop` with `reach` mm around its
    curves: as it is; when `fit`, turned a quarter (if that fits without scaling), else
    scaled down about (0, 0); otherwise `InputError` (saying when a turn would fit)."""
    if drawing.unit != "mm":
        raise InputError(f"place the drawing in mm before hooping (it is in {drawing.unit})")
    xmin, ymin, xmax, ymax = drawing.bounds()
    box = (xmin - reach, ymin - reach, xmax + reach, ymax + reach)
    if hoop.contains(box):
        return Hooped(drawing=drawing)
    # The quarter turn maps (x, y) to (y, -x): the box's sides swap.
    turned_box = (box[1], -box[2], box[3], -box[0])
    turn_fits = hoop.contains(turned_box)
    width, height = box[2] - box[0], box[3] - box[1]
    if not fit:
        raise InputError(_too_big(width, height, hoop, turn_fits))
    if turn_fits:
        return Hooped(drawing=drawing.transformed(QUARTER_TURN, width=drawing.height, height=drawing.width,
                                                  unit="mm", stroke_width=drawing.stroke_width),
                      turned=True)
    # Scale the curves (not the stitch reach) so that curve + reach fits with a margin.
    room_x = hoop.width / 2 - reach - FIT_MARGIN
    room_y = hoop.height / 2 - reach - FIT_MARGIN
    extent_x = max(abs(xmin), abs(xmax), 1e-9)
    extent_y = max(abs(ymin), abs(ymax), 1e-9)
    scale = min(room_x / extent_x, room_y / extent_y)
    if not scale > 0:
        raise InputError(f"hoop {hoop.label} is too small for stitches reaching {reach:g} mm "
                         "either side of the curve")
    matrix = np.array([[scale, 0.0, 0.0], [0.0, scale, 0.0]])
    return Hooped(drawing=drawing.transformed(matrix, width=drawing.width * scale,
                                              height=drawing.height * scale, unit="mm",
                                              stroke_width=drawing.stroke_width * scale),
                  scale=float(scale))


def fit_to_hoop(drawing: Drawing, hoop: Hoop, *, reach: float = 0.0, fit: bool = False) -> Drawing:
    """The drawing of `hoop_design` (the same drawing object when it fits as it is)."""
    return hoop_design(drawing, hoop, reach=reach, fit=fit).drawing


def check_plan_in_hoop(plan: StitchPlan, hoop: Hoop) -> None:
    """Raise `InputError` unless every needle point and jump of `plan` lies in `hoop`."""
    bounds = plan.bounds()
    if not hoop.contains(bounds):
        raise InputError(_too_big(bounds[2] - bounds[0], bounds[3] - bounds[1], hoop))
