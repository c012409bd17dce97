"""Scan-like conditions for the vectorizer benchmark: the clean render, degraded the way
real inputs are (seeded, one generator per drawing).

- clean: the anti-aliased render as it is;
- noisy: Gaussian noise, sigma 0.08 of full scale;
- scan: slightly blurred, paper lit unevenly (0.68-0.98 across the page), gray ink (0.18),
  grain, JPEG at quality 70;
- pencil: light, grainy ink (at most 60 % dark, 45 % of it random grain);
- specks: 60 dust specks 1.5-4 px across scattered over the page;
- varwidth: pen pressure: the line width drifts smoothly between 0.5x and 1.5x;
- half: the page scanned at half the resolution (the output is scaled back to compare);
- gaps: the pen skipped twice: two gaps 1.5 widths (+2 px) long at random places of the
  line's middle 80 %;
- jpeg: the anti-aliased render saved as JPEG at quality 25-50 (ringing and 8x8 blocks
  along every edge);
- breaks: a dry pen: three short breaks across the line, 1 px to 0.6 widths + 1 px long, at
  random places of the line's middle 80 %;
- photo: a phone photo of the page: uneven light, a soft shadow, paper texture, blur, noise,
  colour and JPEG (benchmarks/sets/photo.py; the perspective is in the ground truth of the
  `kinds` set's photos, so this condition alone keeps the geometry).
"""

from __future__ import annotations


import numpy as np
from PIL import Image
from scipy import ndimage

from benchmarks.common.render import render, through_jpeg, to_uint8

CONDITIONS = ("clean", "noisy", "scan", "pencil", "specks", "varwidth", "half", "gaps", "jpeg", "breaks", "photo")


def condition_image(drawing, gray: np.ndarray, condition: str,
                    rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """The uint8 image the vectorizer gets for `drawing` (rendered as `gray`, (H, W) in
    [0, 1]) under `condition`, and the factor from its pixels back to the drawing's."""
    h, w = gray.shape
    if condition == "clean":
        return to_uint8(gray), 1.0
    if condition == "noisy":
        return to_uint8(np.clip(gray + rng.normal(0.0, 0.08, gray.shape), 0, 1)), 1.0
    if condition == "scan":
        yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
        paper = 0.83 + 0.15 * np.cos(2.5 * xx + 1.3 * yy)
        page = 0.18 + (paper - 0.18) * ndimage.gaussian_filter(gray, 0.8)
        page = page + rng.normal(0.0, 0.03, gray.shape)
        return through_jpeg(to_uint8(np.clip(page, 0, 1)), 70), 1.0
    if condition == "pencil":
        cover = (1.0 - gray) * (0.55 + 0.45 * rng.uniform(0.0, 1.0, gray.shape))
        return to_uint8(1.0 - 0.6 * cover), 1.0
    if condition == "specks":
        page = gray.copy()
        yy, xx = np.ogrid[-3:4, -3:4]
        for y, x in zip(rng.integers(3, h - 3, 60), rng.integers(3, w - 3, 60)):
            disc = yy ** 2 + xx ** 2 <= rng.uniform(0.7, 2.0) ** 2
            page[y - 3:y + 4, x - 3:x + 4][disc] = 0.0
        return to_uint8(page), 1.0
    if condition == "varwidth":
        width = drawing.stroke_width
        thin = render(drawing, stroke_width=max(1.5, 0.5 * width))
        thick = render(drawing, stroke_width=1.5 * width)
        field = ndimage.gaussian_filter(rng.normal(size=gray.shape), 60)
        field = (field - field.min()) / (np.ptp(field) + 1e-12)
        return to_uint8(thin * (1.0 - field) + thick * field), 1.0
    if condition == "half":
        small = Image.fromarray(to_uint8(gray)).resize((w // 2, h // 2), Image.LANCZOS)
        return np.asarray(small), w / (w // 2)
    if condition == "jpeg":
        return through_jpeg(to_uint8(gray), int(rng.integers(25, 51))), 1.0
    if condition == "gaps":
        page = gray.copy()
        line = np.concatenate([s.sample_evenly(0.5) for s in drawing.strokes])
        radius = 0.75 * drawing.stroke_width + 1.0
        rows, cols = np.mgrid[0:h, 0:w]
        for _ in range(2):
            x, y = line[rng.integers(len(line) // 10, len(line) * 9 // 10)]
            page[(cols + 0.5 - x) ** 2 + (rows + 0.5 - y) ** 2 <= radius ** 2] = 1.0
        return to_uint8(page), 1.0
    if condition == "breaks":
        page = gray.copy()
        line = np.concatenate([s.sample_evenly(0.5) for s in drawing.strokes])
        rows, cols = np.mgrid[0:h, 0:w]
        for _ in range(3):
            # a band across the line, `length` px along it, wider than the ink
            k = int(rng.integers(len(line) // 10, len(line) * 9 // 10))
            tangent = line[min(k + 2, len(line) - 1)] - line[max(k - 2, 0)]
            tangent /= max(np.linalg.norm(tangent), 1e-9)
            length = rng.uniform(1.0, 0.6 * drawing.stroke_width + 1.0)
            dx, dy = cols + 0.5 - line[k, 0], rows + 0.5 - line[k, 1]
            along = np.abs(dx * tangent[0] + dy * tangent[1])
            across = np.abs(dy * tangent[0] - dx * tangent[1])
            page[(along <= length / 2) & (across <= drawing.stroke_width / 2 + 1.5)] = 1.0
        return to_uint8(page), 1.0
    if condition == "photo":
        from benchmarks.sets.photo import photo_image

        return photo_image(gray, rng), 1.0
    raise ValueError(f"unknown condition {condition!r}; use one of {', '.join(CONDITIONS)}")
