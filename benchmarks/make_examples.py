#!/usr/bin/env python
"""Render a few benchmark drawings to PNG in examples/ (real raster inputs for the README).

    python -m benchmarks.make_examples [--out examples]

Writes examples/<kind>-drawing.png for some generated kinds (seed 0) and two Hershey glyphs
as examples/hershey-<font>-<glyph>.png: 1000 x 1000 px, 8-bit gray, anti-aliased.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from PIL import Image

from benchmarks.sets.drawings import generate_drawing
from benchmarks.sets.hershey import glyph_ground_truth, load_glyphs
from benchmarks.common.render import render, to_uint8

ROOT = Path(__file__).resolve().parents[1]

# (file stem, kind, index): picked for variety of width, crossings and features
GENERATED = [
    ("loop-drawing", "loops", 8),
    ("closed-drawing", "closed", 7),
    ("spike-drawing", "spike", 11),
    ("touch-drawing", "touch", 1),
    ("shallow-crossing-drawing", "shallow", 9),
]
GLYPHS = [("HersheySans1", "ampersand", 4.0), ("HersheySans1", "eight", 5.0)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("--out", type=Path, default=ROOT / "examples")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    written = []
    for stem, kind, index in GENERATED:
        gt = generate_drawing(kind, 0, index)
        path = args.out / f"{stem}.png"
        Image.fromarray(to_uint8(render(gt.drawing))).save(path, optimize=True)
        written.append((path, f"{kind}, width {gt.width:g} px, {len(gt.intersections)} crossings, "
                              f"{gt.count('touch')} touches, {gt.count('spike-tip')} spikes"))
    glyphs = {(g.font, g.name): g for g in load_glyphs()}
    for font, name, width in GLYPHS:
        gt = glyph_ground_truth(glyphs[(font, name)], width)
        path = args.out / f"hershey-{font}-{name}.png"
        Image.fromarray(to_uint8(render(gt.drawing))).save(path, optimize=True)
        written.append((path, f"Hershey glyph, width {width:g} px, {len(gt.intersections)} crossings"))
    for path, what in written:
        print(f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}  {path.stat().st_size // 1024} KB  "
              f"{what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
