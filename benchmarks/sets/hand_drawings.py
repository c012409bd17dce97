"""Two hand drawings of the benchmark's generators as PNG files, for the studio's tests and
benchmarks/studio_edit.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from benchmarks.common.render import render, to_uint8
from benchmarks.sets.drawings import generate_set
from benchmarks.sets.handwriting import handwriting_drawing


def bench_drawing(folder: Path, which: str) -> Path:
    """A hand drawing of the benchmark's generators rendered to a PNG in `folder`: "triple"
    (three passes through a point and three crossings) or "little" (a jittered cursive
    word whose l and t stems are drawn down and back up, with two pen gaps: 11 px of the
    line wiped out at two places)."""
    truth = generate_set("triple", 2, 0)[1] if which == "triple" else handwriting_drawing(0, 3)
    image = to_uint8(render(truth.drawing))
    if which == "little":
        rows, cols = np.nonzero(image < 128)
        for x, y in ((380, 560), (700, 640)):  # the ink nearest these points: an i and the e
            k = int(np.argmin(np.hypot(cols - x, rows - y)))
            image[rows[k] - 5:rows[k] + 6, cols[k] - 5:cols[k] + 6] = 255
    path = folder / f"{truth.name}.png"
    Image.fromarray(image).save(path)
    return path
