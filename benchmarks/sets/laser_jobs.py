"""Drawings for the laser tests and benchmarks: a smooth single stroke, Hershey text, a spiral."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

HERSHEY = Path(__file__).resolve().parents[1] / "data" / "hershey" / "HersheyScriptMed.svg"


def catmull_rom_stroke(points: np.ndarray, closed: bool = False) -> Stroke:
    """A C1 cubic Bézier spline through `points` (N, 2) (Catmull-Rom tangents)."""
    p = np.asarray(points, dtype=float)
    if closed:
        p = np.vstack([p, p[:1]])
        ext = np.vstack([p[-2:-1], p, p[1:2]])
    else:
        ext = np.vstack([2 * p[0] - p[1], p, 2 * p[-1] - p[-2]])
    tangent = (ext[2:] - ext[:-2]) / 2.0
    a, b = p[:-1], p[1:]
    return Stroke(np.stack([a, a + tangent[:-1] / 3.0, b - tangent[1:] / 3.0, b], axis=1))


def rose_drawing(knots: int = 60, petals: int = 5, size: float = 400.0) -> Drawing:
    """One closed self-crossing stroke (a rose curve with a twist), px, y down."""
    t = np.linspace(0, 2 * np.pi, knots, endpoint=False)
    r = 0.35 * size * (0.55 + 0.45 * np.cos(petals * t / 2) ** 2)
    pts = np.c_[size / 2 + r * np.cos(t), size / 2 + r * np.sin(1.0 * t) * 0.8 + 0.05 * size * np.sin(3 * t)]
    return Drawing((catmull_rom_stroke(pts, closed=True),), size, size, "px", 3.0)


def wiggle_drawing(segments: int, *, size: float = 1000.0, seed: int = 0) -> Drawing:
    """One long open stroke of `segments` cubic segments wandering over the canvas (px)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, segments + 1)
    x = size * (0.5 + 0.45 * np.sin(2 * np.pi * 7 * t) * np.cos(2 * np.pi * 3 * t))
    y = size * (0.5 + 0.45 * np.sin(2 * np.pi * 5 * t + 0.3))
    pts = np.c_[x, y] + rng.normal(0, 0.3, (segments + 1, 2))
    return Drawing((catmull_rom_stroke(pts),), size, size, "px", 2.0)


def hershey_text_drawing(text: str = "onestroke laser") -> Drawing:
    """Text in Hershey Script (single-line font): many polyline strokes, px, y down."""
    svg = HERSHEY.read_text()
    glyphs = {}
    for m in re.finditer(r'<glyph unicode="([^"]*)"[^>]*?horiz-adv-x="([\d.]+)"(?:[^>]*?d="([^"]*)")?', svg):
        glyphs[m.group(1)] = (float(m.group(2)), m.group(3) or "")
    strokes, x = [], 0.0
    for ch in text:
        adv, d = glyphs.get(ch, (400.0, ""))
        for sub in re.split(r"(?=M)", d):
            nums = np.array(re.findall(r"[-+]?\d*\.?\d+", sub), dtype=float)
            if len(nums) >= 4:
                pts = nums.reshape(-1, 2)
                pts = np.c_[pts[:, 0] + x, 1000.0 - pts[:, 1]]  # font y up -> y down
                if np.ptp(pts, axis=0).max() > 0:
                    strokes.append(Stroke.from_polyline(pts))
        x += adv
    return Drawing(tuple(strokes), x, 1200.0, "px", 20.0)


def spiral_points(segment: float = 0.05, turns: float = 8.0, r0: float = 2.0, pitch: float = 1.5,
                  centre=(100.0, 100.0)) -> np.ndarray:
    """An Archimedean spiral as a polyline of segments `segment` mm long: (N, 2) mm."""
    # arc length of r = r0 + b*theta grows ~ r dtheta; step theta so each chord is ~segment
    b = pitch / (2 * np.pi)
    theta, pts = 0.0, []
    end = 2 * np.pi * turns
    while theta <= end:
        r = r0 + b * theta
        pts.append((centre[0] + r * np.cos(theta), centre[1] + r * np.sin(theta)))
        theta += segment / np.hypot(r, b)
    return np.array(pts)


def straight_line_job(feed: float) -> list[str]:
    """G-code of one 537 mm diagonal burn at `feed` mm/min. G4P0 makes GRBL stop after the
    rapid, so the burn starts from rest."""
    return ["G21", "G90", "M4S0", "G0X10Y10", "G4P0", f"G1X390Y390S600F{feed:g}", "M5", "M9"]


def spiral_job(feed: float) -> list[str]:
    """G-code of a 6-turn spiral of 0.05 mm segments at `feed` mm/min (the planner's worst
    case: thousands of tiny blocks with a junction each)."""
    pts = spiral_points(segment=0.05, turns=6.0, r0=2.0, pitch=1.2)
    body = ["G1X%.3fY%.3f" % tuple(p) for p in pts[1:]]
    body[0] += f"S600F{feed:g}"
    return ["G21", "G90", "M4S0", "G0X%.3fY%.3f" % tuple(pts[0])] + body + ["M5", "M9"]


def trefoil_png(path, size: int = 500, width: int = 7):
    """A raster single-line drawing with three self-crossings (trefoil), for the vectorizer."""
    from PIL import Image, ImageDraw

    t = np.linspace(0, 2 * np.pi, 2000)
    x = np.sin(t) + 2 * np.sin(2 * t)
    y = np.cos(t) - 2 * np.cos(2 * t)
    pts = np.c_[size / 2 + 0.14 * size * x, size / 2 + 0.14 * size * y]
    image = Image.new("L", (size, size), 255)
    ImageDraw.Draw(image).line([tuple(p) for p in pts.tolist()], fill=0, width=width, joint="curve")
    image.save(path)
    return path
