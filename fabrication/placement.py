"""Placement: a `Drawing` in pixels becomes millimetres, scaled to a size and centred on (0, 0).

Embroidery uses the centred frame as is (pyembroidery's +y is down, like ours); the laser
planner moves it to the machine's origin and flips y there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing

# A design side from 0.1 mm (one needle or laser step) to 10 m (past any bed or hoop).
SIDE = Range(0.1, 10_000.0, unit="mm", name="--size")
ROTATE = Range(-360.0, 360.0, unit="degrees", name="--rotate")
DPI = Range(0.0, None, name="dpi", low_open=True)


@dataclass(frozen=True, kw_only=True)
class PlacementOptions:
    """Target size of the design in mm. Give at most one of `size`, `width`, `height`.

    size: longest side; width / height: that side (0.1 mm-10 m); none: keep the drawing's
    own size (pixels read at `dpi`). rotate: degrees, counter-clockwise as seen on screen.
    """

    size: float | None = ranged(None, SIDE)
    width: float | None = ranged(None, SIDE.named("--width"))
    height: float | None = ranged(None, SIDE.named("--height"))
    rotate: float = ranged(0.0, ROTATE)
    dpi: float = ranged(96.0, DPI)

    def __post_init__(self) -> None:
        check_ranges(self)
        given = [n for n, v in (("size", self.size), ("width", self.width), ("height", self.height)) if v is not None]
        if len(given) > 1:
            raise InputError(f"give only one of --size, --width, --height (got {', '.join(given)})")


def place(drawing: Drawing, options: PlacementOptions = PlacementOptions()) -> Drawing:
    """Scale, rotate and centre `drawing` on (0, 0) in millimetres.

    The returned drawing's canvas is its bounding box size; stroke width scales with it.
    """
    if not drawing.strokes:
        raise InputError("the drawing has no strokes to place")
    angle = np.radians(options.rotate)
    # y points down, so a counter-clockwise turn on screen is a negative math angle.
    rot = np.array([[np.cos(angle), np.sin(angle)], [-np.sin(angle), np.cos(angle)]])
    rotated = drawing.transformed(np.hstack([rot, np.zeros((2, 1))]), width=drawing.width,
                                  height=drawing.height, unit=drawing.unit,
                                  stroke_width=drawing.stroke_width)
    xmin, ymin, xmax, ymax = rotated.bounds()
    w, h = xmax - xmin, ymax - ymin
    if options.size is not None:
        scale = options.size / max(w, h, 1e-12)
    elif options.width is not None:
        scale = options.width / max(w, 1e-12)
    elif options.height is not None:
        scale = options.height / max(h, 1e-12)
    else:
        scale = 1.0 if drawing.unit == "mm" else 25.4 / options.dpi
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    matrix = np.array([[scale, 0.0, -scale * cx], [0.0, scale, -scale * cy]])
    return rotated.transformed(matrix, width=max(w * scale, 1e-9), height=max(h * scale, 1e-9),
                               unit="mm", stroke_width=drawing.stroke_width * scale)


def place_on_page(drawing: Drawing, options: PlacementOptions | None = None) -> Drawing:
    """`drawing` in millimetres on a page of its physical size, for SVG documents read by
    other tools (Ink/Stitch, laser senders, vpype); the origin is the page's top-left corner.

    options None: the input's own page read at 96 dpi (a drawing in px is scaled, nothing
    moves, so a caller can map the result back onto the input). Otherwise the drawing is
    `place`d and its box starts half an ink width from the page's corner, so the drawn
    line's round caps stay on the page (the page is the box plus that margin).
    """
    if options is None:
        scale = 1.0 if drawing.unit == "mm" else 25.4 / PlacementOptions().dpi
        return drawing.transformed(np.array([[scale, 0.0, 0.0], [0.0, scale, 0.0]]),
                                   width=drawing.width * scale, height=drawing.height * scale, unit="mm",
                                   stroke_width=drawing.stroke_width * scale)
    placed = place(drawing, options)
    margin = placed.stroke_width / 2
    dx, dy = placed.width / 2 + margin, placed.height / 2 + margin
    return placed.transformed(np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]]), width=placed.width + 2 * margin,
                              height=placed.height + 2 * margin, unit="mm", stroke_width=placed.stroke_width)
