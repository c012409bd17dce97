"""The satin previews of issue 27, each beside its input: a brush drawing, an acute corner, a
short stroke; and the zigzag at the wave drawing's sharpest fold. Run from the repository
root: python docs/notes/2026-12-05/satin_previews.py
Writes satin-brush.png, satin-corner.png, satin-short.png and zigzag-fold.png next to this
file (input on the left, its whole page; the realistic preview on the right, framed to the
design, or for the fold and the corner's tip a close-up of the place, the needle points
shown).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(ROOT))

from benchmarks.sets.brush import kana_set  # noqa: E402
from benchmarks.common.render import render, render_truth, to_uint8  # noqa: E402
from fabrication.embroidery.pipeline import EmbroideryJob, embroider  # noqa: E402
from fabrication.embroidery.plan import PlanOptions  # noqa: E402
from fabrication.embroidery.preview import PreviewOptions, render_stitch_preview, stitch_canvas  # noqa: E402
from fabrication.embroidery.columns import find_corners  # noqa: E402
from fabrication.embroidery.sampling import dense_curve  # noqa: E402
from fabrication.embroidery.satin import SatinOptions  # noqa: E402
from fabrication.embroidery.zigzag import ZigzagOptions  # noqa: E402
from fabrication.placement import PlacementOptions  # noqa: E402
from machines.hoops import hoop_named  # noqa: E402
from vectorize.drawing import Drawing  # noqa: E402
from vectorize import VectorizeOptions, vectorize_file  # noqa: E402
from vectorize.pipeline import vectorize_image  # noqa: E402
from vectorize.stroke import Stroke  # noqa: E402

SIDE = 640  # px of each half
THREAD = (31, 95, 168)


def side_by_side(gray: np.ndarray, drawing, size: float, out: Path, label: str, *, style=None,
                 close_up: float = 0.0) -> None:
    """Vectorize `gray` (or take `drawing`), sew it at `size` mm (`style`: satin by default),
    save input | preview; `close_up` > 0: the preview shows the sharpest corner's
    surroundings, that many mm either side, with its needle points."""
    style = style if style is not None else SatinOptions()
    with tempfile.TemporaryDirectory() as folder:
        job = EmbroideryJob(placement=PlacementOptions(size=size), hoop=hoop_named("200x200"),
                            plan=PlanOptions(style=style, colors=(THREAD,)))
        result = embroider(drawing if drawing is not None else vectorize_image(gray).drawing, job)
        if close_up:
            preview = _close_up(result.plan, close_up, f"{folder}/p.png")
        else:
            render_stitch_preview(result.plan, f"{folder}/p.png", options=PreviewOptions(width=SIDE))
            preview = Image.open(f"{folder}/p.png").convert("RGB")
    source = Image.fromarray(gray).convert("RGB")
    source.thumbnail((SIDE, SIDE))
    height = max(source.height, preview.height)
    sheet = Image.new("RGB", (2 * SIDE + 10, height + 28), (255, 255, 255))
    sheet.paste(source, (0, 28))
    sheet.paste(preview, (SIDE + 10, 28))
    ImageDraw.Draw(sheet).text((6, 6), f"{label}: input (left), --style {type(style).__name__[:-7].lower()}, "
                               f"{size:g} mm (right{', close-up of the sharpest corner' if close_up else ''}); "
                               f"{result.stats.stitches} stitches, density max {result.stats.max_density}",
                               fill=(20, 20, 20))
    sheet.save(out, optimize=True)


def _close_up(plan, half: float, path: str) -> Image.Image:
    """The realistic preview of `plan` around its sharpest corner, `half` mm either side,
    SIDE px square (cut from a preview 4000 px wide)."""
    corner, turn = None, -1.0
    for stroke in plan.sewn.strokes:
        curve = dense_curve(stroke)
        for c in find_corners(stroke, curve, np.full(len(curve.s), 1.0), 20.0):
            if c.turn > turn:
                corner, turn = c.point, c.turn
    canvas = stitch_canvas(plan, options=PreviewOptions(width=4000, stats=False))
    image = canvas.to_image().convert("RGB")
    cx, cy = canvas.px(np.asarray(corner)[None, :])[0]
    r = half * canvas.scale
    return image.crop(tuple(int(round(v)) for v in (cx - r, cy - r, cx + r, cy + r))).resize((SIDE, SIDE), Image.LANCZOS)


def main() -> None:
    brush = kana_set(3)[0]  # a brush kana: pressed in, swelling, swept out
    side_by_side(to_uint8(render_truth(brush)), None, 80.0, HERE / "satin-brush.png", "brush kana")
    # an acute corner: two legs 30 degrees apart, a 24 px pen on a 1000 px page
    turn = np.radians(150.0)
    legs = np.array([[250.0, 300.0], [700.0, 520.0]])
    tip = legs[1] + 420.0 * np.array([np.cos(np.radians(25.0) + turn), np.sin(np.radians(25.0) + turn)])
    v = Drawing((Stroke.from_polyline(np.vstack([legs, tip])),), 1000, 1000, "px", 24.0)
    side_by_side(to_uint8(render(v)), None, 60.0, HERE / "satin-corner.png", "30 degree corner", close_up=4.0)
    # a short stroke beside a long one (the short one just above --min-stroke at 40 mm)
    short = Drawing((Stroke.from_polyline(np.array([[300.0, 400.0], [330.0, 400.0]])),
                     Stroke.from_polyline(np.array([[300.0, 600.0], [700.0, 600.0]]))), 1000, 1000, "px", 24.0)
    # (sewn from the strokes themselves: single-line vectorizing keeps the largest piece only)
    side_by_side(to_uint8(render(short)), short, 40.0, HERE / "satin-short.png", "a 3 mm stroke and a 40 mm one")
    # the zigzag at the wave drawing's sharpest fold (examples/embroidery/wave.svg, 90 mm)
    wave = vectorize_file(str(ROOT / "examples" / "embroidery" / "wave.svg"), VectorizeOptions()).drawing
    side_by_side(to_uint8(render(wave)), wave, 90.0, HERE / "zigzag-fold.png", "the wave's fold",
                 style=ZigzagOptions(), close_up=4.0)


if __name__ == "__main__":
    main()
