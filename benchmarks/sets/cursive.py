"""Long cursive words and short sentences written as one line, with the joins of real cursive.

The `handwriting` set's words are short and clean at the joins. Here a whole line of 10-40
letters is one pen path (words joined by their connecting strokes, as a pen that never
lifts writes them), from the handwriting set's letters plus a and m, with what real cursive
adds at the joins and in the loops:

- **overshoot hooks**: where the connecting stroke arrives at a letter's entry cusp (the
  tops of i, u, y and p), the pen runs on past it, bent 15-45 degrees, and comes back:
  a free stub beside the junction (`HOOK_CHANCE` per cusp);
- **entry stubs** of m and n: a short tick up and to the left from the entry cusp, drawn
  out and back (`STUB_CHANCE`);
- **ascender and descender loops** (the retraced stems of d, k, l, t and the descender of
  p): the way back drifts sideways from the way out, by up to `DRIFT` widths in the middle,
  and meets it again at both ends, so the two passes lie within a width of each other;
- no i-dots or t-bars (pen lifts).

Each stub and stem adds two odd-degree junctions to the ink's graph (its tip and its base),
so a line has 16-70 of them (`meta["odd_nodes"]`, counted on the ink graph).

The line is scaled to the canvas (its x-height follows from its length: ~20 px for 40
letters, up to 120 px for 10), with a width of 4.5-8 % of the x-height (2-8 px), then traced
as a mouse records it (`handwriting._mouse_trace`, with a gentler wobble so the stems'
passes stay within a width). The ground truth is the traced polyline; its ink graph and
minimum traversal come from the path before drift and jitter (where each stem and stub is
exactly one segment drawn twice), scaled by the traced length over that path's length.
Every drawing retraces, so every drawing is scored by the fair-retrace rule where its order
score misses (docs/benchmark.md).
"""

from __future__ import annotations

import numpy as np
import shapely

from benchmarks.metrics.ground_truth import CANVAS, MARGIN, GroundTruth
from benchmarks.sets.handwriting import (
    LEAD_IN,
    LETTERS,
    _mouse_trace,
    _runs_stroke,
    on_the_page,
    retraced_runs,
    traced_crossings,
)
from benchmarks.metrics.ink import fair_meta
from benchmarks.metrics.table1 import ambiguous_junctions
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

# Two more letters in the handwriting set's units (x-height 1): a (d's bowl with a stem up to
# the x-height, drawn up and back down) and m (n with two arches).
ALPHABET = {
    **LETTERS,
    "a": (1.05, [[(0.7, 0.85), (0.4, 1.0), (0.1, 0.6), (0.2, 0.1), (0.55, 0.0), (0.8, 0.4)],
                 [(0.8, 0.4), (0.88, 1.1)], [(0.88, 1.1), (0.8, 0.4)],
                 [(0.8, 0.4), (0.78, 0.12), (0.9, 0.0), (1.1, 0.12)]]),
    "m": (1.75, [[(0.37, 0.85)], [(0.37, 0.85), (0.36, 0.45)], [(0.36, 0.45), (0.35, 0.0)],
                 [(0.35, 0.0), (0.36, 0.45)],
                 [(0.36, 0.45), (0.6, 0.92), (0.82, 0.78), (0.83, 0.45)], [(0.83, 0.45), (0.82, 0.0)],
                 [(0.82, 0.0), (0.83, 0.45)],
                 [(0.83, 0.45), (1.08, 0.92), (1.35, 0.78), (1.37, 0.25), (1.5, 0.0), (1.8, 0.12)]]),
}
# Long words and short sentences of those letters, 10-40 letters each.
LINES = (
    "inauthentically", "the kitten ate the mauled candy", "hand me the lamp the tent and the kettle",
    "phenylalanine", "a neat little pink candle", "uncle hank decided at lunchtime", "acetaldehyde",
    "mail the ticket at ten", "the planet men tend the yacht", "unethically", "death in the attic",
    "handy lady tidy attic", "incidentally", "the little duck had tea", "make a tidy paddle",
    "mechanically", "the cat needed a nap", "accidentally", "i like mint tea at midday", "unpunctuated",
    "the chemical plant in the dell", "methylamine", "an empty cup and a dull pen", "identically",
    "a lady in the yacht needed a dim lamp and a cup", "unintended and unattended", "the mad hatted duke met a lady",
    "technically", "a pale tailed kitten", "academically", "the kettle and the teacup", "dialectical",
    "the mean duke hated the tiny candle in the attic", "antiacademic", "the hunted elk came at ten", "unmechanical",
    "he hummed the name", "ethnically", "the acid ate the metal", "unhealthily",
)
SPACE = 0.45  # extra x-height units between words (the connecting stroke runs through it)
HOOK_CHANCE = 0.4  # an overshoot hook at a letter's entry cusp
HOOKED = "iuyp"  # letters entered at a cusp at the x-height (t, l, k, d start their stem at the entry)
STUB_CHANCE = 0.7  # an entry stub at m and n
DRIFT = (0.3, 1.0)  # widths the way back up or down a stem drifts from the way out, in the middle
DRIFT_MIN_LENGTH = 0.8  # x-heights: stems from this long (ascenders, descenders) drift
WOBBLE = 0.25  # widths of the mouse trace's slow wobble (handwriting: 0.4)


def _turned(v: np.ndarray, degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]) @ v


def line_runs(text: str, rng: np.random.Generator) -> list[np.ndarray]:
    """The runs of a line's pen path in x-height units (y up), as `handwriting.word_runs`
    makes them, with hooks and stubs at the entry cusps (module doc). Retraced stretches are
    exact here (drift comes later, in px)."""
    runs: list[list] = [[LEAD_IN]]
    x = 0.0
    for w, word in enumerate(text.split()):
        x += SPACE if w else 0.0
        for ch in word:
            advance, letter = ALPHABET[ch]
            placed = [[(px + x, py) for px, py in run] for run in letter]
            runs[-1] = runs[-1] + placed[0]  # the connecting stroke: one smooth run through both
            if len(placed[0]) == 1 and len(runs[-1]) >= 2:  # an entry cusp: the pen turns back here
                cusp = np.array(runs[-1][-1])
                arrival = cusp - np.array(runs[-1][-2])
                arrival /= max(np.linalg.norm(arrival), 1e-9)
                tip = None
                if ch in "mn" and rng.random() < STUB_CHANCE:
                    tip = cusp + rng.uniform(0.15, 0.3) * _turned(np.array([-0.35, 1.0]) / 1.06, rng.uniform(-15, 15))
                elif ch in HOOKED and rng.random() < HOOK_CHANCE:
                    bend = rng.choice([-1.0, 1.0]) * rng.uniform(15.0, 45.0)
                    tip = cusp + rng.uniform(0.15, 0.35) * _turned(arrival, bend)
                if tip is not None:
                    runs += [[tuple(cusp), tuple(tip)], [tuple(tip), tuple(cusp)]]
            runs += placed[1:]
            x += advance
    return [np.array(r, dtype=float) for r in runs]


def _drifted(run: np.ndarray, offset: float) -> np.ndarray:
    """A straight run (2, 2) px bowed sideways by `offset` px in the middle (a sine arch),
    meeting the straight line at both ends: (9, 2) waypoints of a smooth run."""
    a, b = run
    t = np.linspace(0.0, 1.0, 9)
    normal = np.array([-(b - a)[1], (b - a)[0]]) / max(np.linalg.norm(b - a), 1e-9)
    return a + t[:, None] * (b - a) + offset * np.sin(np.pi * t)[:, None] * normal


def cursive_drawing(seed: int, index: int, text: str | None = None) -> GroundTruth:
    """One long cursive line, determined by (seed, index); `text` (letters of `ALPHABET` and
    spaces) instead of the set's line for that index."""
    rng = np.random.default_rng([seed, index, 24])
    text = text or LINES[(index + 11 * seed) % len(LINES)]
    runs = line_runs(text, rng)
    slant = rng.uniform(0.1, 0.35)
    runs, scale = on_the_page(runs, slant, np.radians(rng.uniform(-3.0, 3.0)), CANVAS - 2 * (MARGIN + 20), 120.0)
    width = float(np.clip(np.round(scale * rng.uniform(0.045, 0.08) * 4) / 4, 2.0, 8.0))
    back = retraced_runs(runs)
    clean, clean_poly, _ = _runs_stroke(runs)
    drawn = list(runs)
    long_stems = [k for k in back if np.linalg.norm(runs[k][1] - runs[k][0]) >= DRIFT_MIN_LENGTH * scale]
    for k in long_stems:
        drawn[k] = _drifted(runs[k], rng.choice([-1.0, 1.0]) * rng.uniform(*DRIFT) * width)
    pen, pen_poly, pen_ends = _runs_stroke(drawn)
    run_lengths = np.cumsum([0.0] + [float(np.linalg.norm(np.diff(pen_poly[a:b + 1], axis=0), axis=1).sum())
                                     for a, b in zip([0] + pen_ends[:-1], pen_ends)])
    trace = _mouse_trace(rng, pen, run_lengths[1:-1] * pen.length / run_lengths[-1], width, wobble=WOBBLE)
    stroke = Stroke.from_polyline(trace)
    fair = fair_meta(clean_poly, ambiguous=bool(ambiguous_junctions(clean_poly)), scale=stroke.length / clean.length)
    stems = [shapely.LineString(runs[k]).buffer(width * (1.0 + DRIFT[1])) for k in back]
    crossings, events, dont_care = traced_crossings(trace, stroke, clean, clean_poly, stems, width)
    drawing = Drawing((stroke,), CANVAS, CANVAS, unit="px", stroke_width=width)
    letters = sum(len(word) for word in text.split())
    return GroundTruth(name=f"cursive-{text.replace(' ', '_')}-{seed}-{index}", kind="cursive", drawing=drawing,
                       closed=False, intersections=crossings, events=events, dont_care=dont_care,
                       meta={"seed": seed, "index": index, "text": text, "letters": letters, "width": width,
                             "x_height": scale, "retraces": len(back), "drifted": len(long_stems),
                             **fair,
                             "clean_length": clean.length})


def cursive_set(count: int = 40, seed: int = 0) -> list[GroundTruth]:
    """`count` long cursive lines (module doc), deterministic for a seed."""
    return [cursive_drawing(seed, index) for index in range(count)]
