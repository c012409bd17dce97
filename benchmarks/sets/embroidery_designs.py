"""The embroidery test designs: drawings in mm (strokes, a spiral, a three-colour SVG) and the
styles and formats every design is sewn and written in, for the tests and
benchmarks/embroidery_quality.py."""

from __future__ import annotations

import numpy as np

from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

# Three colours; red twice, far apart, so one colour block holds two strokes.
THREE_COLOURS = """<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 100 100">
<path d="M10 10 C 30 0 50 20 60 10" stroke="#c81e28" fill="none"/>
<path d="M10 40 C 30 30 50 50 60 40" stroke="rgb(20,120,40)" fill="none"/>
<g stroke="navy" fill="none"><path d="M10 70 C 30 60 50 80 60 70"/></g>
<path d="M70 10 L 90 90" stroke="#c81e28" fill="none"/>
</svg>
"""

STYLE_NAMES = ("running", "triple", "zigzag", "arrows")
FORMATS = ("pes", "dst", "jef", "exp", "vp3")


def spiral(cx: float, cy: float, r0: float, r1: float, turns: float, n: int = 24) -> Stroke:
    """A smooth spiral as cubic segments (Hermite to Bézier), radius r0 -> r1 mm."""
    th = np.linspace(0.0, 2 * np.pi * turns, n + 1)
    r = r0 + (r1 - r0) * th / th[-1]
    p = np.c_[cx + r * np.cos(th), cy + r * np.sin(th)]
    dr = (r1 - r0) / th[-1]
    d = np.c_[dr * np.cos(th) - r * np.sin(th), dr * np.sin(th) + r * np.cos(th)]  # dp/dtheta
    h = np.diff(th)[:, None] / 3.0
    control = np.stack([p[:-1], p[:-1] + d[:-1] * h, p[1:] - d[1:] * h, p[1:]], axis=1)
    return Stroke(control)


def s_curve_with_corner() -> Stroke:
    """Two smooth cubic arcs, then a sharp (about 120 degree) corner into a straight leg."""
    control = np.array([
        [[-40, -20], [-30, -45], [-10, -45], [0, -20]],
        [[0, -20], [10, 5], [30, 5], [35, -20]],
        [[35, -20], [30, -23], [25, -26], [20, -29]],
    ], dtype=float)
    return Stroke(control)


def design() -> Drawing:
    """Four strokes in mm around (0, 0): an S with a corner, a spiral 2 mm after it ends
    (joined by a travel stitch), a far straight line (trim + jump) and a short wiggle."""
    first = s_curve_with_corner()
    end = first.end
    second = spiral(end[0] - 2.0 - 4.0, end[1], 4.0, 9.0, 1.5)  # starts 2 mm left of `end`
    third = Stroke.from_polyline(np.array([[-35.0, 30.0], [10.0, 38.0]]))
    fourth = spiral(25.0, 30.0, 2.0, 5.0, 1.0, n=12)
    return Drawing((first, second, third, fourth), 100, 100, "mm")
