"""Helpers of the bridge tests: the real `onestroke` command, and SVG paths read back with svgelements."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import svgelements as se


def onestroke(*args, cwd=None) -> subprocess.CompletedProcess:
    """Run the installed `onestroke` command line (this interpreter) and return the process."""
    return subprocess.run([sys.executable, "-m", "fabrication.cli", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd)


def svg_curves(path) -> list[np.ndarray]:
    """Every `<path>` of an SVG in document order, as cubic control points (K, 4, 2) in the
    document's px (svgelements applies the viewBox and every transform); lines count as
    straight cubics and a new sub-path (`M`) starts a new curve."""
    curves = []
    for element in se.SVG.parse(str(path), reify=True).elements():
        if not isinstance(element, se.Path):
            continue
        segments = []
        for segment in element.segments():
            if isinstance(segment, se.Move):
                if segments:
                    curves.append(np.array(segments))
                segments = []
            elif isinstance(segment, se.CubicBezier):
                segments.append([[p.x, p.y] for p in (segment.start, segment.control1, segment.control2,
                                                      segment.end)])
            elif isinstance(segment, (se.Line, se.Close)) and segment.start != segment.end:
                a, b = np.array(segment.start), np.array(segment.end)
                segments.append([a, a + (b - a) / 3, a + 2 * (b - a) / 3, b])
        if segments:
            curves.append(np.array(segments, dtype=float))
    return curves


def moved(control: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Control points (..., 2) through a 3x3 affine matrix."""
    return control @ matrix[:2, :2].T + matrix[:2, 2]


def affine(a=1.0, b=0.0, c=0.0, d=1.0, e=0.0, f=0.0) -> np.ndarray:
    """SVG's matrix(a b c d e f) as 3x3."""
    return np.array([[a, c, e], [b, d, f], [0.0, 0.0, 1.0]])


def rotation(degrees: float) -> np.ndarray:
    r = np.radians(degrees)
    return affine(np.cos(r), np.sin(r), -np.sin(r), np.cos(r))


def curve_points(control: np.ndarray, samples: int = 40) -> np.ndarray:
    """Points on cubic segments (K, 4, 2), `samples` per segment in order: (K * samples, 2)."""
    t = np.linspace(0, 1, samples)[:, None, None]
    points = ((1 - t) ** 3 * control[:, 0] + 3 * (1 - t) ** 2 * t * control[:, 1]
              + 3 * (1 - t) * t * t * control[:, 2] + t ** 3 * control[:, 3])
    return points.transpose(1, 0, 2).reshape(-1, 2)
