"""Small constructed drawings (px, y down) rendered the way a scanner would see them."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw


def render_polylines(polylines, size=(400, 400), width=6.0, supersample=4) -> np.ndarray:
    """Anti-aliased black polylines on white: uint8 (H, W). Round caps and joins."""
    w, h = size
    s = supersample
    image = Image.new("L", (w * s, h * s), 255)
    draw = ImageDraw.Draw(image)
    r = width * s / 2
    for line in polylines:
        pts = [(float(x) * s, float(y) * s) for x, y in line]
        draw.line(pts, fill=0, width=max(1, int(round(width * s))), joint="curve")
        for x, y in pts:
            draw.ellipse([x - r, y - r, x + r, y + r], fill=0)
    return np.asarray(image.resize((w, h), Image.LANCZOS))


def circle(cx=200, cy=200, radius=120, n=400):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[cx + radius * np.cos(t), cy + radius * np.sin(t)]


def figure_eight(n=600):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[200 + 150 * np.sin(t), 200 + 100 * np.sin(2 * t)]


def alpha_loop(n=600):
    """An open curve that loops once and crosses itself (a trochoid arc)."""
    t = np.linspace(-2.9, 2.9, n)
    return np.c_[200 + 45 * t - 110 * np.sin(t), 200 - 110 * np.cos(t)]


def v_spike():
    """Out along a line and back at a slight angle: an out-and-back spike with a sharp tip."""
    return np.array([[60.0, 200.0], [330.0, 200.0], [80.0, 240.0]])


def cursive_stretch(seed: int, index: int, center: tuple[float, float], half: float):
    """The stretch of a cursive set line's pen path from its first to its last point within
    `half` px of `center`, moved onto a small page: (Drawing, the ground-truth crossing
    nearest `center` on that page (2,) px)."""
    from benchmarks.sets.cursive import cursive_drawing
    from vectorize.drawing import Drawing
    from vectorize.stroke import Stroke

    gt = cursive_drawing(seed, index)
    points = gt.drawing.strokes[0].sample_evenly(1.0)
    inside = np.flatnonzero(np.all(np.abs(points - np.array(center)) < half, axis=1))
    path = points[inside.min():inside.max() + 1]
    shift = 20.0 - path.min(axis=0)
    crossings = np.asarray(gt.intersections, dtype=float).reshape(-1, 2)
    crossing = crossings[np.argmin(np.linalg.norm(crossings - np.array(center), axis=1))] + shift
    size = path.max(axis=0) + shift + 20.0
    return Drawing((Stroke.from_polyline(path + shift),), float(size[0]), float(size[1]), "px", gt.width), crossing
