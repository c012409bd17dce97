"""A folder of small drawings for the batch benchmark and tests.

The bundled example PNGs shrunk to SIZE px, Hershey glyphs rendered at SIZE px, the
bundled wave SVG, and (optionally) one truncated PNG; some of them in a subfolder.
Deterministic: the same files every time.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from benchmarks.sets.hershey import glyph_stroke, load_glyphs
from benchmarks.common.render import render, to_uint8
from vectorize.drawing import Drawing

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ("closed-drawing", "hershey-HersheySans1-ampersand", "hershey-HersheySans1-eight", "loop-drawing",
            "loops", "shallow-crossing-drawing", "spike-drawing", "touch-drawing")
# HersheySans1 glyphs drawn in one stroke, picked by name (open, closed, with loops).
GLYPHS = tuple(("HersheySans1", name) for name in ("two", "three", "five", "six", "nine", "C", "J", "S", "U", "e"))
SIZE = 360  # px, longest side
GLYPH_WIDTH = 6.0  # px ink width


def _glyph_image(font: str, name: str, glyphs) -> np.ndarray:
    glyph = next(g for g in glyphs if g.font == font and g.name == name)
    stroke, _, _ = glyph_stroke(glyph)
    control = stroke.control
    low, high = control.reshape(-1, 2).min(axis=0), control.reshape(-1, 2).max(axis=0)
    margin = 40.0
    scale = (SIZE - 2 * margin) / float((high - low).max())
    placed = (control - low) * scale + margin
    drawing = Drawing(strokes=(type(stroke)(placed),), width=SIZE, height=SIZE, stroke_width=GLYPH_WIDTH)
    return to_uint8(render(drawing))


def make_drawing_folder(folder: str | Path, *, corrupt: bool = True, count: int | None = None) -> list[Path]:
    """Write the drawings into `folder` (created; "sub/" holds part of them); returns their
    paths, the corrupt one last. count: keep only the first `count` good drawings."""
    folder = Path(folder)
    (folder / "sub").mkdir(parents=True, exist_ok=True)
    made: list[Path] = []
    for index, name in enumerate(EXAMPLES):
        with Image.open(ROOT / "examples" / f"{name}.png") as image:
            image.thumbnail((SIZE, SIZE), Image.LANCZOS)
            path = folder / ("sub" if index % 3 == 0 else "") / f"{name}.png"
            image.save(path)
        made.append(path)
    glyphs = load_glyphs()
    for index, (font, name) in enumerate(GLYPHS):
        path = folder / ("sub" if index % 2 else "") / f"glyph-{font}-{name}.png"
        Image.fromarray(_glyph_image(font, name, glyphs)).save(path)
        made.append(path)
    svg = folder / "sub" / "wave.svg"
    svg.write_bytes((ROOT / "examples" / "embroidery" / "wave.svg").read_bytes())
    made.append(svg)
    if count is not None:
        for path in made[count:]:
            path.unlink()
        made = made[:count]
    if corrupt:
        bad = folder / "sub" / "scan-cut-short.png"
        bad.write_bytes(made[0].read_bytes()[:200])  # a PNG header and no picture
        made.append(bad)
    return made
