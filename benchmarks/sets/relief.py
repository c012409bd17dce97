"""Relief SingleLine glyphs as benchmark drawings: smooth cubic Bézier single-line lettering
drawn by type designers (benchmarks/data/relief, a copy of ../shared/data/relief with its
OFL licence and README).

The glyphs drawn with one move-to go through the same rules and ground truth as the
Hershey glyphs (benchmarks/sets/hershey.py: scaled to the canvas, seeded width 3-8 px, crossings
and touches found on the exact curve, ambiguous or crowded glyphs left out). Size variants
of one shape (".numr", ".dnom", ".subs", ".osf", ...) count once: the first by name. Many
closed shapes (O, circle, squares, triangles, 0, 8) end a unit or two short of where they
started: a glyph whose ends lie within one width of each other counts as closed (its ink is
a closed loop, the start cannot be seen, so an output may start anywhere on it).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from benchmarks.metrics.ground_truth import GroundTruth
from benchmarks.sets.hershey import Glyph, hershey_set, load_glyphs

RELIEF_DIR = Path(__file__).resolve().parents[1] / "data" / "relief"


def relief_glyphs(directory: Path | str = RELIEF_DIR) -> list[Glyph]:
    """Single-move-to Relief glyphs, one per base name (the part before the first dot)."""
    seen: set[str] = set()
    out = []
    for glyph in sorted(load_glyphs(directory), key=lambda g: (g.name.split(".")[0], g.name)):
        base = glyph.name.split(".")[0]
        if base not in seen:
            seen.add(base)
            out.append(glyph)
    return out


def relief_set(count: int = 40, seed: int = 0) -> list[GroundTruth]:
    """`count` Relief glyphs (those with crossings first, up to 70 %), deterministic for a seed;
    kinds "relief-crossing", "relief-simple", ..."""
    chosen = hershey_set(count, seed, glyphs=relief_glyphs(), close_gaps=True)
    return [replace(gt, kind=gt.kind.replace("hershey", "relief")) for gt in chosen]
