"""Outline-only SVG drawings: fill the outline rings into a gray image for the pipeline.

Stock line art is often stored as the contour of its ink (filled, not stroked). Filling it
even-odd at the working size gives the same kind of raster the pipeline reads from a
scan, and the result is mapped back into the SVG's own units.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw
from skimage.transform import downscale_local_mean

# Supersampling factor of the fill: enough anti-aliasing for a sub-pixel outline.
SUPERSAMPLE = 4


def rasterize_rings(rings, *, size: int) -> tuple[np.ndarray, float, np.ndarray]:
    """Fill closed rings (list of (N, 2) in SVG units) even-odd into a gray image.

    Returns (gray (H, W) float32, 1 = paper; scale = working px per SVG unit; offset (2,)
    = SVG position of the corner of working pixel (0, 0)). The image covers the rings' bounds plus a
    margin, with its longest side `size` px.
    """
    everything = np.vstack(rings)
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    extent = float(max(hi - lo)) or 1.0
    margin = 0.03 * extent
    lo, hi = lo - margin, hi + margin
    scale = (size - 1) / float(max(hi - lo))
    shape = (int(np.ceil((hi[1] - lo[1]) * scale)) + 1, int(np.ceil((hi[0] - lo[0]) * scale)) + 1)
    big = (shape[0] * SUPERSAMPLE, shape[1] * SUPERSAMPLE)
    ink = np.zeros(big, dtype=bool)
    for ring in rings:
        # Pillow fills whole pixels between rounded vertices (scanline, fast for rings of
        # thousands of points); big pixel p covers [p, p + 1) of the supersampled frame.
        xy = (ring - lo) * scale * SUPERSAMPLE - 0.5
        mask = Image.new("1", (big[1], big[0]), 0)
        ImageDraw.Draw(mask).polygon([tuple(p) for p in xy.tolist()], fill=1)
        ink ^= np.asarray(mask, dtype=bool)  # even-odd: holes cancel
    gray = 1.0 - downscale_local_mean(ink.astype(np.float32), (SUPERSAMPLE, SUPERSAMPLE))
    return gray.astype(np.float32), scale, lo
