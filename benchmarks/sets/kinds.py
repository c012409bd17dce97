"""The `kinds` set: kinds of real single-line drawings no other set holds (issue 10's new
users): TSP art, brush kana, broad-nib capitals and phone photos of pen drawings.

- tsp (benchmarks/sets/tsp_art.py): one closed line through 2500-4500 stipple points, no
  crossing, passes 1-3 px of paper apart wherever the tone is dark;
- brush-kana, brush-capital (benchmarks/sets/brush.py): the ink width changes 3x along the line
  (pressure and tapered ends; a broad nib's thick and thin);
- photo (benchmarks/sets/photo.py): a handwriting word, a Hershey or Relief glyph, a generated
  drawing or a brush kana at seeds no other set uses (their sources' seed + 5, + 5000 for the
  generator), seen in slight perspective and stored as a phone's JPEG (condition "photo").

Sources are interleaved so that the first `count` mix every kind. Scoring is that of the
other sets, with the excursion measured against half the LOCAL width + 1 px where the width
varies (meta "width_profile").
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely
import shapely.affinity

from benchmarks.metrics.ground_truth import GroundTruth, interleaved

SEED_OFFSET = 5  # photo sources: a seed the other sets do not use
# drawings per kind at the default count (40)
SHARES = {"tsp": 6, "brush-kana": 12, "brush-capital": 10, "photo": 12}


def photo_sources(count: int, seed: int) -> list[GroundTruth]:
    """Drawings to photograph: the sources in turn (module doc)."""
    from benchmarks.sets.brush import kana_set
    from benchmarks.sets.drawings import generate_set
    from benchmarks.sets.handwriting import handwriting_drawing
    from benchmarks.sets.hershey import hershey_set
    from benchmarks.sets.relief import relief_set

    s = seed + SEED_OFFSET
    n = count // 5 + 1
    queues = [[handwriting_drawing(s, i) for i in range(n)], hershey_set(n, s), relief_set(n, s),
              generate_set("plain", n, 1000 * s), kana_set(n, s)]
    return interleaved(queues, count)


def kinds_set(count: int | None = None, seed: int = 0) -> list[GroundTruth]:
    """The `kinds` drawings (module doc): `count` (default 40) with every kind in proportion,
    deterministic for a seed."""
    from benchmarks.sets.brush import capital_set, kana_set
    from benchmarks.sets.photo import photographed
    from benchmarks.sets.tsp_art import tsp_drawing

    total = sum(SHARES.values())
    count = total if count is None else count
    share = {k: int(np.ceil(v * count / total)) for k, v in SHARES.items()}
    rng = np.random.default_rng([seed, 59])
    sources = {
        "tsp": [tsp_drawing(seed, i) for i in range(share["tsp"])],
        "brush-kana": kana_set(share["brush-kana"], seed),
        "brush-capital": capital_set(share["brush-capital"], seed),
        "photo": [photographed(gt, rng) for gt in photo_sources(share["photo"], seed)],
    }
    return interleaved(sources.values(), count)


def scaled(gt: GroundTruth, factor: float) -> GroundTruth:
    """`gt` drawn `factor` times larger on a canvas `factor` times larger (a 3000-4000 px
    page of the same drawing): geometry, widths, width profile and minimum length scaled."""
    d = gt.drawing
    drawing = d.transformed(np.array([[factor, 0.0, 0.0], [0.0, factor, 0.0]]), width=d.width * factor,
                            height=d.height * factor, unit=d.unit, stroke_width=d.stroke_width * factor)
    meta = {**gt.meta, "scale": factor}
    if "width_profile" in meta:
        knots, widths = meta["width_profile"]
        meta["width_profile"] = (knots, np.asarray(widths) * factor)
    for key in ("min_length", "route_min"):
        if key in meta:
            meta[key] = meta[key] * factor
    zones = tuple(shapely.affinity.scale(z, factor, factor, origin=(0, 0)) if isinstance(z, shapely.Geometry)
                  else np.asarray(z) * factor for z in gt.dont_care)
    return replace(gt, name=f"{gt.name}-x{factor:g}", drawing=drawing, intersections=gt.intersections * factor,
                   events=tuple(replace(e, point=np.asarray(e.point) * factor, radius=e.radius * factor)
                                for e in gt.events), dont_care=zones, meta=meta)
