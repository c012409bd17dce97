"""Anti-aliased rendering of a `Drawing` for the benchmark: gray float in [0, 1], 1 = paper.

A distance field: every pixel near the ink gets the exact distance d from its centre to the
nearest centre line (strokes sampled every 0.2 px, nearest sample by a k-d tree; the chord
error is below 0.01 px), and its ink coverage is clip(w/2 - d + 1/2, 0, 1), the area a
straight edge covers in a unit pixel. This gives round caps and joins for free and, unlike a
polygon rasterizer, does not depend on how finely the curve was cut into segments, so the
ground truth and an output that follows the same curve render to the same pixels.

`render_profile` draws one stroke whose width changes along it (a brush, a broad nib,
foreshortening in a photo): coverage is the largest clip(w(s)/2 - d + 1/2) over discs
centred along the centre line.
"""

from __future__ import annotations

import io

import numpy as np
from PIL import Image
from scipy import ndimage
from scipy.spatial import cKDTree

from vectorize.drawing import Drawing

SAMPLE_SPACING = 0.2  # px along the centre line


def render(drawing: Drawing, *, stroke_width: float | None = None, size: tuple[int, int] | None = None) -> np.ndarray:
    """Render `drawing` (px) on its canvas: (H, W) float64 in [0, 1], 1 = paper, 0 = full ink.

    stroke_width: ink width in px (default: the drawing's own); size: (W, H) canvas in px
    (default: the drawing's width and height, rounded). Pixel (row r, column c) covers
    x in [c, c + 1), y in [r, r + 1).
    """
    if size is None:
        size = (int(round(drawing.width)), int(round(drawing.height)))
    width, height = size
    w = float(drawing.stroke_width if stroke_width is None else stroke_width)
    image = np.ones((height, width), dtype=np.float64)
    if not drawing.strokes:
        return image
    samples = np.concatenate([s.sample_evenly(SAMPLE_SPACING) for s in drawing.strokes])
    # pixels that can receive ink: within w/2 + 1.5 px of a sample's pixel
    cols = np.floor(samples[:, 0]).astype(int)
    rows = np.floor(samples[:, 1]).astype(int)
    inside = (cols >= -1) & (cols <= width) & (rows >= -1) & (rows <= height)
    seed = np.zeros((height + 2, width + 2), dtype=bool)
    seed[rows[inside] + 1, cols[inside] + 1] = True
    if not seed.any():
        return image
    reach = w / 2 + 1.5
    band = ndimage.distance_transform_edt(~seed) <= reach
    band = band[1:-1, 1:-1]
    r, c = np.nonzero(band)
    centres = np.c_[c + 0.5, r + 0.5]
    d, _ = cKDTree(samples).query(centres, distance_upper_bound=reach + 1.0)
    coverage = np.clip(w / 2 - d + 0.5, 0.0, 1.0)
    image[r, c] = 1.0 - coverage
    return image


PROFILE_SPACING = 0.5  # px between the discs `render_profile` unites (edge scallops < 0.02 px deep)
SPLAT_CHUNK = 4_000_000  # (disc, pixel) pairs evaluated at a time


def profile_widths(profile: tuple[np.ndarray, np.ndarray], fractions: np.ndarray) -> np.ndarray:
    """Widths (px) at `fractions` (0-1) of the arc length, from a profile (knot fractions
    (K,) increasing from 0 to 1, widths (K,) px)."""
    knots, widths = profile
    return np.interp(fractions, np.asarray(knots, dtype=float), np.asarray(widths, dtype=float))


def render_profile(drawing: Drawing, profile: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Render a one-stroke `drawing` (px) whose ink width follows `profile` (see
    `profile_widths`) along its arc length: (H, W) float64 in [0, 1], 1 = paper.

    The ink is the union of discs of the local radius r centred every PROFILE_SPACING px on the
    centre line; a pixel's coverage is the largest clip(r - d + 1/2, 0, 1) over the discs (d:
    its centre's distance to the disc's), the constant-width `render` with r varying."""
    width, height = int(round(drawing.width)), int(round(drawing.height))
    samples = drawing.strokes[0].sample_evenly(PROFILE_SPACING)
    radii = profile_widths(profile, np.linspace(0.0, 1.0, len(samples))) / 2
    reach = int(np.ceil(radii.max() + 1.5))
    oy, ox = (a.ravel() for a in np.mgrid[-reach:reach + 1, -reach:reach + 1])
    coverage = np.zeros(height * width)
    step = max(1, SPLAT_CHUNK // len(ox))
    for lo in range(0, len(samples), step):
        p, r = samples[lo:lo + step], radii[lo:lo + step, None]
        cols = np.floor(p[:, :1]).astype(int) + ox
        rows = np.floor(p[:, 1:]).astype(int) + oy
        d = np.hypot(cols + 0.5 - p[:, :1], rows + 0.5 - p[:, 1:])
        cov = np.clip(r - d + 0.5, 0.0, 1.0)
        ok = (cov > 0.0) & (cols >= 0) & (cols < width) & (rows >= 0) & (rows < height)
        index = rows * width + cols
        edge = ok & (cov < 1.0)
        np.maximum.at(coverage, index[edge], cov[edge])
        coverage[index[ok & (cov >= 1.0)]] = 1.0  # full cover: nothing exceeds it
    return 1.0 - coverage.reshape(height, width)


def render_truth(gt) -> np.ndarray:
    """A benchmark `GroundTruth` rendered: with its width profile (meta "width_profile")
    when it has one, else at its constant stroke width."""
    profile = gt.meta.get("width_profile")
    return render(gt.drawing) if profile is None else render_profile(gt.drawing, profile)


def to_uint8(gray: np.ndarray) -> np.ndarray:
    """Gray float in [0, 1] to uint8 (what a PNG holds and what the vectorizer is given)."""
    return np.clip(np.round(gray * 255.0), 0, 255).astype(np.uint8)


def through_jpeg(image: np.ndarray, quality: int, subsampling: int = -1) -> np.ndarray:
    """`image` (uint8, gray or RGB) through a JPEG file at `quality` (Pillow's chroma
    subsampling unless given: 2 is 4:2:0, a phone's)."""
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, "JPEG", quality=quality, subsampling=subsampling)
    return np.asarray(Image.open(buffer))
