"""route-technically.png: one cursive line (benchmarks/sets/cursive.py, seed 0 index 27, 18 odd
junctions) vectorized by two versions of the vectorizer, stretches drawn twice in red.

    python docs/notes/2026-12-05/route_preview.py OLD_TREE NEW_TREE

OLD_TREE and NEW_TREE are source trees (git worktrees) whose `vectorize` is run, each in its
own process; the benchmark's drawing comes from this tree.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
SEED, INDEX = 0, 27
RUN = """
import sys, numpy as np
sys.path.insert(0, sys.argv[1])
from vectorize import VectorizeOptions, vectorize_image
sys.path.insert(1, sys.argv[2])
from benchmarks.sets.cursive import cursive_drawing
from benchmarks.common.render import render_truth, to_uint8
gt = cursive_drawing({seed}, {index})
result = vectorize_image(to_uint8(render_truth(gt)), VectorizeOptions())
np.save(sys.argv[3], np.vstack([s.sample_evenly(0.5) for s in result.drawing.strokes]))
"""


def outline(tree: str, dest: Path) -> np.ndarray:
    subprocess.run([sys.executable, "-c", RUN.format(seed=SEED, index=INDEX), tree, str(ROOT), str(dest)], check=True)
    return np.load(dest)


def panel(points: np.ndarray, gray: np.ndarray, width: float, box: tuple, label: str, minimum: float) -> Image.Image:
    """The line over the light ink: blue where drawn once, red where it runs over ink it draws
    again more than 6 widths further along."""
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    twice = np.array([any(abs(s[j] - s[i]) > 6 * width for j in near)
                      for i, near in enumerate(cKDTree(points).query_ball_point(points, r=0.35 * width))])
    from benchmarks.common.render import to_uint8

    im = Image.fromarray(to_uint8(0.78 + 0.22 * gray)).convert("RGB")
    draw = ImageDraw.Draw(im)
    for k in range(len(points) - 1):
        red = twice[k] and twice[k + 1]
        draw.line([tuple(points[k]), tuple(points[k + 1])], fill=(220, 30, 30) if red else (30, 60, 200),
                  width=3 if red else 1)
    im = im.crop(box)
    out = Image.new("RGB", (im.width, im.height + 22), "white")
    out.paste(im, (0, 22))
    ImageDraw.Draw(out).text((6, 5), f"{label}: {s[-1]:.0f} px drawn, {100 * twice.mean():.0f} % of it on ink it "
                                     f"draws twice (shortest line over the ink: {minimum:.0f} px)", fill=(0, 0, 0))
    return out


def main() -> None:
    sys.path.insert(0, str(ROOT))
    from benchmarks.sets.cursive import cursive_drawing
    from benchmarks.common.render import render_truth

    gt = cursive_drawing(SEED, INDEX)
    gray = render_truth(gt)
    ys, xs = np.nonzero(gray < 0.5)
    box = (int(xs.min() - 15), int(ys.min() - 15), int(xs.max() + 15), int(ys.max() + 15))
    labels = ("before (greedy matching above 14 odd nodes)", "after (one exact blossom matching)")
    with tempfile.TemporaryDirectory() as tmp:
        panels = [panel(outline(tree, Path(tmp) / f"{k}.npy"), gray, gt.width, box, label, gt.meta["route_min"])
                  for k, (tree, label) in enumerate(zip(sys.argv[1:3], labels))]
    out = Image.new("RGB", (panels[0].width, sum(p.height for p in panels)), "white")
    for k, p in enumerate(panels):
        out.paste(p, (0, k * panels[0].height))
    out.save(HERE / "route-technically.png", optimize=True)


if __name__ == "__main__":
    main()
