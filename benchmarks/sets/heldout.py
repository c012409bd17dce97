"""The held-out set: drawings and rendering conditions the other benchmark sets do not hold,
to check that the vectorizer's junction decisions generalise beyond what the sets tune for.

Sources (none of them a drawing of another set at seed 0, the seed the team tunes on):

- Hershey glyphs that neither `hershey` nor `hershey-retrace` (`hershey_set(40, 0)` and its
  ambiguous twin) take: those with a crossing or retrace first, then simple ones, and
  ambiguous ones scored by the fair-retrace rule. The glyph rules are those of
  benchmarks/sets/hershey.py except that crossings may come within 1 width (not 3) of each
  other's ink-merge zones, of an end, of a retrace or of a merged narrow turn: the crowded
  junctions real lettering has (most glyphs the `hershey` set leaves out are left out for
  that), and that a Hershey glyph whose ends lie within one width counts as closed, as Relief
  glyphs do;
- Relief SingleLine glyphs that `relief` (`relief_set(40, 0)`) does not take, same rules;
- handwriting words that `handwriting` at seed 0 does not write (`WORDS[40:]`);
- generated plain, touch and triple drawings at another seed (1000 + seed).

Glyphs get a width of 2-12 px (the other glyph sets: 3-8) and a size of 55-100 % of the
canvas's room, and every other glyph is turned by -40..40 degrees about the canvas centre.
Each drawing is rendered under one of `CONDITIONS` in turn (benchmarks/sets/conditions.py:
clean, paper scan, heavy JPEG, noise, pen pressure, dry-pen breaks, half resolution,
pencil), stored as meta "condition" and in the drawing's name.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely
import shapely.affinity

from benchmarks.sets.drawings import generate_set
from benchmarks.metrics.ground_truth import CANVAS, MARGIN, GroundTruth, interleaved
from benchmarks.sets.handwriting import WORDS, handwriting_drawing
from benchmarks.sets.hershey import hershey_set, load_glyphs
from benchmarks.sets.relief import relief_glyphs, relief_set
from vectorize.drawing import Drawing

CONDITIONS = ("clean", "scan", "jpeg", "noisy", "varwidth", "breaks", "half", "pencil")
TUNED_SEED = 0  # the seed the other sets are tuned and reported at
# a glyph whose ends lie within one width of each other is closed (its ink is a loop: where
# the pen started cannot be seen), for Hershey glyphs too
GLYPH_RULES = {"spacing": 1.0, "widths": (2.0, 12.0), "sizes": (0.55, 1.0), "close_gaps": True}
# drawings per source at the default count (93)
SHARES = {"hershey": 24, "hershey-fair": 16, "relief": 16, "handwriting": 17, "plain": 8, "touch": 8,
          "triple": 4}


def turned(gt: GroundTruth, degrees: float) -> GroundTruth | None:
    """`gt` turned by `degrees` about the canvas centre (all its geometry), or None when the
    turned ink would come nearer than MARGIN to the canvas edge."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    m = CANVAS / 2
    matrix = np.array([[c, -s, m - c * m + s * m], [s, c, m - s * m - c * m]])
    strokes = tuple(st.transformed(matrix) for st in gt.drawing.strokes)
    pts = np.concatenate([st.sample_evenly(2.0) for st in strokes])
    half = gt.width / 2
    if pts.min() - half < MARGIN or pts.max() + half > CANVAS - MARGIN:
        return None

    def move(p):
        return np.asarray(p, dtype=float) @ matrix[:, :2].T + matrix[:, 2]

    shapely_matrix = [matrix[0, 0], matrix[0, 1], matrix[1, 0], matrix[1, 1], matrix[0, 2], matrix[1, 2]]
    zones = tuple(shapely.affinity.affine_transform(z, shapely_matrix) if isinstance(z, shapely.Geometry)
                  else move(z) for z in gt.dont_care)
    drawing = Drawing(strokes, gt.drawing.width, gt.drawing.height, unit=gt.drawing.unit,
                      stroke_width=gt.drawing.stroke_width)
    events = tuple(replace(e, point=move(e.point)) for e in gt.events)
    return replace(gt, drawing=drawing, intersections=move(gt.intersections).reshape(-1, 2), events=events,
                   dont_care=zones, meta={**gt.meta, "turned": float(degrees)})


def _glyph_sources(seed: int) -> dict[str, list[GroundTruth]]:
    """The held-out glyphs by source, each glyph turned or not (module doc)."""
    used = {(gt.meta["font"], gt.meta["glyph"]) for gt in
            hershey_set(40, TUNED_SEED) + hershey_set(40, TUNED_SEED, ambiguous=True)}
    hershey = [g for g in load_glyphs() if (g.font, g.name or g.unicode) not in used]
    used_relief = {gt.meta["glyph"] for gt in relief_set(40, TUNED_SEED)}
    relief = [g for g in relief_glyphs() if g.name not in used_relief]
    out = {
        "hershey": hershey_set(SHARES["hershey"], seed, glyphs=hershey, **GLYPH_RULES),
        "hershey-fair": hershey_set(SHARES["hershey-fair"], seed, glyphs=hershey, ambiguous=True, **GLYPH_RULES),
        "relief": [replace(gt, kind=gt.kind.replace("hershey", "relief")) for gt in
                   hershey_set(SHARES["relief"], seed, glyphs=relief, **GLYPH_RULES)],
    }
    rng = np.random.default_rng([seed, 31])
    for source, gts in out.items():
        for k, gt in enumerate(gts):
            angle = rng.uniform(-40.0, 40.0)
            if k % 2:
                gts[k] = turned(gt, angle) or gt
    return out


def heldout_set(count: int | None = None, seed: int = 0) -> list[GroundTruth]:
    """The held-out drawings (module doc), sources interleaved so that the first `count`
    (default all, 93) mix every source; deterministic for a seed."""
    sources = _glyph_sources(seed)
    words = [(w - 7 * seed) % len(WORDS) for w in range(40, len(WORDS))]  # WORDS[40:] at this seed
    sources["handwriting"] = [handwriting_drawing(seed, i) for i in words[:SHARES["handwriting"]]]
    for name in ("plain", "touch", "triple"):
        sources[name] = generate_set(name, SHARES[name], 1000 + seed)
    out = []
    for k, gt in enumerate(interleaved(sources.values(), count)):
        condition = CONDITIONS[k % len(CONDITIONS)]
        out.append(replace(gt, name=f"{gt.name}-{condition}", meta={**gt.meta, "condition": condition}))
    return out
