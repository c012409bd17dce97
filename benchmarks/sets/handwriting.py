"""Generated cursive handwriting with hand jitter, as benchmark drawings with ground truth.

A word is written in one stroke from lowercase letters drawn as pen paths: loops (e, h, y),
retraced up-and-down strokes (the stems of d, k, l, t and the descender of p drawn down
and back up the same line; the first stroke of n and h retraced from the baseline), cusps
(the tips of those stems, the tops of i and u) and connecting strokes between letters.
Dots and crossbars, which need a pen lift, are left out. The word is slanted, scaled to the
canvas (x-height 70-170 px) and given a seeded width of 3-8 px.

Then it is traced as a mouse or tablet would record it: the pen path is sampled every 3-7
px (the spacing drifts with the hand's speed, cusps are always sampled), every sample is
moved by a slow wobble (a smooth random displacement along the path, at most 0.4 widths,
so the two passes of a retraced stem wander around each other within one width) and by
sample-corner noise (0.3 px Gaussian, then rounded to whole pixels). The ground truth is
that jittered polyline, in pen order.

The ink graph (for the fair-retrace rule and the ambiguity test) comes from the path before
jitter, where a retraced stem is exactly one segment drawn twice; its minimum traversal
length is scaled by the jitter's length factor. Intersections are those of the jittered
path; the retraced stems, narrow cusps and places where two passes run within one width
without crossing are don't-care zones for them.
"""

from __future__ import annotations

import numpy as np
import shapely

from benchmarks.sets.drawings import _hermite, _Waypoint
from benchmarks.metrics.ground_truth import CANVAS, MARGIN, Event, GroundTruth
from benchmarks.sets.hershey import _sharp_turns
from benchmarks.metrics.ink import fair_meta
from benchmarks.metrics.table1 import (
    MATCH_DISTANCE,
    ambiguous_junctions,
    dont_care_mask,
    merged_without_crossing,
    polyline_intersections,
    tiny_loop_crossings,
)
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

# Letters in x-height units (baseline y = 0, x-height 1, ascender 2, descender -1, y up).
# Each letter is (advance, runs): a run of 3+ points is a smooth curve through them, a run
# of 2 points a straight line; consecutive runs meet in a cusp. A retraced stretch is a
# straight run followed by its exact reverse. The first point is where the connecting
# stroke from the previous letter arrives; the last is where the next one leaves.
LETTERS: dict[str, tuple[float, list[list[tuple[float, float]]]]] = {
    "c": (0.95, [[(0.8, 0.85), (0.5, 1.0), (0.15, 0.7), (0.15, 0.25), (0.45, 0.0), (0.9, 0.1)]]),
    "d": (1.05, [[(0.75, 0.85), (0.4, 1.0), (0.1, 0.6), (0.2, 0.1), (0.55, 0.0), (0.8, 0.4)],
                 [(0.8, 0.4), (0.9, 2.0)], [(0.9, 2.0), (0.8, 0.4)],
                 [(0.8, 0.4), (0.78, 0.12), (0.9, 0.0), (1.1, 0.12)]]),
    "e": (0.9, [[(0.1, 0.3), (0.6, 0.6), (0.55, 0.95), (0.25, 0.85), (0.12, 0.45), (0.35, 0.02), (0.8, 0.1)]]),
    "h": (1.1, [[(0.0, 0.25), (0.3, 0.75), (0.55, 1.3), (0.58, 1.8), (0.42, 1.98), (0.28, 1.75), (0.24, 1.2),
                 (0.22, 0.8)],
                [(0.22, 0.8), (0.2, 0.3)], [(0.2, 0.3), (0.19, 0.0)], [(0.19, 0.0), (0.2, 0.3)],
                [(0.2, 0.3), (0.5, 0.85), (0.75, 0.75), (0.76, 0.25), (0.88, 0.0), (1.12, 0.12)]]),
    "i": (0.85, [[(0.55, 0.9)], [(0.55, 0.9), (0.52, 0.3), (0.60, 0.0), (0.90, 0.12)]]),
    "k": (1.1, [[(0.22, 0.05)], [(0.22, 0.05), (0.3, 2.0)], [(0.3, 2.0), (0.22, 0.05)],
                [(0.22, 0.05), (0.5, 0.55), (0.8, 0.9), (0.88, 0.7), (0.58, 0.5)],
                [(0.58, 0.5), (0.78, 0.2), (0.92, 0.0), (1.15, 0.12)]]),
    "l": (0.7, [[(0.3, 0.45)], [(0.3, 0.45), (0.42, 2.0)], [(0.42, 2.0), (0.3, 0.45)],
                [(0.3, 0.45), (0.28, 0.12), (0.42, 0.0), (0.75, 0.12)]]),
    "n": (1.30, [[(0.37, 0.85)], [(0.37, 0.85), (0.36, 0.45)], [(0.36, 0.45), (0.35, 0.0)],
                 [(0.35, 0.0), (0.36, 0.45)],
                 [(0.36, 0.45), (0.65, 0.92), (0.95, 0.78), (0.97, 0.25), (1.10, 0.0), (1.35, 0.12)]]),
    "p": (1.35, [[(0.45, 0.9)], [(0.45, 0.9), (0.43, 0.4)], [(0.43, 0.4), (0.37, -1.0)], [(0.37, -1.0), (0.43, 0.4)],
                [(0.43, 0.4), (0.70, 0.92), (1.03, 0.8), (1.07, 0.3), (1.20, 0.0), (1.40, 0.12)]]),
    "t": (0.75, [[(0.3, 0.45)], [(0.3, 0.45), (0.4, 1.6)], [(0.4, 1.6), (0.3, 0.45)],
                 [(0.3, 0.45), (0.28, 0.12), (0.42, 0.0), (0.8, 0.12)]]),
    "u": (1.30, [[(0.40, 0.9)], [(0.40, 0.9), (0.40, 0.3), (0.60, 0.0), (0.85, 0.3), (0.95, 0.9)],
                 [(0.95, 0.9), (1.01, 0.25), (1.11, 0.0), (1.35, 0.12)]]),
    "y": (1.25, [[(0.40, 0.9)], [(0.40, 0.9), (0.40, 0.3), (0.60, 0.0), (0.83, 0.3), (0.93, 0.9)],
                [(0.93, 0.9), (0.99, 0.0), (0.93, -0.7), (0.70, -0.97), (0.58, -0.72), (0.87, -0.2), (1.25, 0.15)]]),
}
# Words with a crossing between each free end and the nearest retraced stem, so the drawing
# order can be read from the ink (order score; checked by the tests) ...
READABLE = ("cute", "ethic", "hike", "icky", "elite", "hue", "cycle", "city", "icicle", "ethnic", "eddy",
            "cutie", "dye", "dice", "duke", "dude", "deuce", "dunce", "deduce", "decide", "delete", "dike",
            "cede", "yule", "yucky", "eke", "elude", "entice", "ducky", "due", "clue", "dicey", "dully", "cite",
            "hey", "etc", "ditty", "dietetic", "elide", "idle", "idly", "icily", "deity", "celtic", "eclectic")
# ... and words that start or end next to a retraced stem (t, l, d, k, n, p), where two free
# branches meet and either could be the retraced one (fair-retrace rule)
AMBIGUOUS = ("little", "kettle", "puddle", "tickle", "needle", "tilde", "kind", "deck", "tent", "lend", "pink",
             "dip")
# every fourth drawing is an ambiguous word
WORDS = tuple(w for k in range(0, len(READABLE), 3) for w in READABLE[k:k + 3] + AMBIGUOUS[k // 3:k // 3 + 1])
LEAD_IN = (-0.35, 0.0)  # where the pen starts, before the first letter's connecting stroke


def word_runs(word: str) -> list[np.ndarray]:
    """The runs of a word's pen path in x-height units: the letters placed side by side, each
    connecting stroke merged into the smooth runs on both sides of it."""
    runs: list[list[tuple[float, float]]] = [[LEAD_IN]]
    x = 0.0
    for ch in word:
        advance, letter = LETTERS[ch]
        placed = [[(px + x, py) for px, py in run] for run in letter]
        runs[-1] = runs[-1] + placed[0]  # the connecting stroke: one smooth run through both
        runs += placed[1:]
        x += advance
    return [np.array(r, dtype=float) for r in runs]


def _runs_stroke(runs: list[np.ndarray]) -> tuple[Stroke, np.ndarray, list[int]]:
    """One stroke through the runs, its exact polyline (run ends kept exactly, so a retraced
    segment and its reverse coincide) and the polyline index of every run end."""
    controls, poly, ends = [], [runs[0][0]], []
    for run in runs:
        if len(run) == 2:
            piece, _ = _hermite([_Waypoint(run[0]), _Waypoint(run[1])], closed=False)
            pts = np.array([run[0], run[1]])
        else:
            piece, _ = _hermite([_Waypoint(p) for p in run], closed=False)
            pts = piece.flatten(0.05)
            pts[0], pts[-1] = run[0], run[-1]
        controls.append(piece.control)
        poly.extend(pts[1:])
        ends.append(len(poly) - 1)
    return Stroke(np.concatenate(controls)), np.array(poly), ends


def _wobble(rng: np.random.Generator, s: np.ndarray, amplitude: float) -> np.ndarray:
    """A smooth displacement (len(s), 2) along arc length s: a few slow sinusoids per axis,
    scaled so that its largest length is `amplitude`."""
    out = np.zeros((len(s), 2))
    for axis in range(2):
        for _ in range(3):
            wavelength = rng.uniform(120.0, 400.0)
            out[:, axis] += rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * s / wavelength + rng.uniform(0, 2 * np.pi))
    return out * amplitude / max(np.linalg.norm(out, axis=1).max(), 1e-9)


def _mouse_trace(rng: np.random.Generator, stroke: Stroke, cusp_lengths: np.ndarray, width: float,
                 wobble: float = 0.4) -> np.ndarray:
    """The stroke as a mouse or tablet records it (module doc): jittered samples, px; the slow
    wobble is at most `wobble` widths."""
    s, steps = [0.0], 0
    speed = rng.uniform(3.0, 7.0)
    while s[-1] < stroke.length:
        steps += 1
        speed = float(np.clip(speed + rng.normal(0.0, 0.5), 3.0, 7.0))
        s.append(s[-1] + speed)
    s = np.unique(np.clip(np.concatenate([s, cusp_lengths, [stroke.length]]), 0.0, stroke.length))
    pts = stroke.points_at_lengths(s) + _wobble(rng, s, wobble * width)
    pts = np.round(pts + rng.normal(0.0, 0.3, pts.shape))
    keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]
    return pts[keep]


def on_the_page(runs: list[np.ndarray], slant: float, turn: float, room: float,
                max_scale: float) -> tuple[list[np.ndarray], float]:
    """Runs in x-height units (y up) slanted (x += slant * y), flipped (y down on the page),
    turned by `turn` radians, scaled to fit `room` px (at most `max_scale` px per x-height)
    and centred on the canvas: (runs px, px per x-height)."""
    c, s_ = np.cos(turn), np.sin(turn)
    shape = np.array([[c, -s_], [s_, c]]) @ np.array([[1.0, slant], [0.0, -1.0]])
    pts = np.concatenate(runs) @ shape.T
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    scale = min(room / (hi - lo).max(), max_scale)
    offset = np.array([CANVAS / 2, CANVAS / 2]) - scale * (lo + hi) / 2
    return [r @ (scale * shape).T + offset for r in runs], float(scale)


def retraced_runs(runs: list[np.ndarray]) -> list[int]:
    """Indices of the runs that go back exactly over the run before them (a retraced stem)."""
    return [k for k in range(1, len(runs)) if len(runs[k]) == 2 and len(runs[k - 1]) == 2
            and np.array_equal(runs[k - 1][::-1], runs[k])]


def traced_crossings(trace: np.ndarray, stroke: Stroke, clean: Stroke, clean_poly: np.ndarray,
                     retraced_zones: list, width: float) -> tuple[np.ndarray, tuple, tuple]:
    """The crossings of a traced word ((n, 2) px), their events and the don't-care zones: the
    retraced stems' zones given, narrow cusps, passes within one width without a crossing, and
    loops too small to hold paper. Crossings of the jittered passes of a retraced stem or a
    cusp are not crossings of the word."""
    inter = polyline_intersections([trace], [False])
    dont_care = list(retraced_zones) + _sharp_turns(clean_poly, False, width)
    dont_care += merged_without_crossing(clean, False, width, polyline_intersections([clean_poly], [False]).crossings)
    dont_care += tiny_loop_crossings(stroke, False, width, inter.crossings)
    real = ~dont_care_mask(inter.crossings, dont_care, max(MATCH_DISTANCE, width))
    crossings, angles = inter.crossings[real], inter.crossing_angles[real]
    events = tuple(Event("crossing", p, float(a)) for p, a in zip(crossings, angles))
    return crossings.reshape(-1, 2), events, tuple(dont_care)


def handwriting_drawing(seed: int, index: int) -> GroundTruth:
    """One jittered cursive word, determined by (seed, index)."""
    rng = np.random.default_rng([seed, index, 7])
    word = WORDS[(index + 7 * seed) % len(WORDS)]
    width = float(np.round(rng.uniform(3.0, 8.0) * 4) / 4)
    runs = word_runs(word)
    slant = rng.uniform(0.1, 0.35)
    runs, scale = on_the_page(runs, slant, np.radians(rng.uniform(-5.0, 5.0)), CANVAS - 2 * (MARGIN + width + 10), 170.0)
    clean, clean_poly, ends = _runs_stroke(runs)
    run_lengths = np.cumsum([0.0] + [float(np.linalg.norm(np.diff(clean_poly[a:b + 1], axis=0), axis=1).sum())
                                     for a, b in zip([0] + ends[:-1], ends)])
    trace = _mouse_trace(rng, clean, run_lengths[1:-1] * clean.length / run_lengths[-1], width)
    stroke = Stroke.from_polyline(trace)
    fair = fair_meta(clean_poly, ambiguous=bool(ambiguous_junctions(clean_poly)), scale=stroke.length / clean.length)
    retraced = [shapely.LineString(runs[k]) for k in retraced_runs(runs)]
    crossings, events, dont_care = traced_crossings(trace, stroke, clean, clean_poly,
                                                    [g.buffer(width) for g in retraced], width)
    drawing = Drawing((stroke,), CANVAS, CANVAS, unit="px", stroke_width=width)
    return GroundTruth(name=f"hand-{word}-{seed}-{index}", kind="handwriting", drawing=drawing, closed=False,
                       intersections=crossings, events=events, dont_care=dont_care,
                       meta={"seed": seed, "index": index, "word": word, "width": width, "x_height": scale,
                             "retraces": len(retraced), **fair, "clean_length": clean.length})


def handwriting_set(count: int = 40, seed: int = 0) -> list[GroundTruth]:
    """`count` jittered cursive words (module doc), deterministic for a seed."""
    return [handwriting_drawing(seed, index) for index in range(count)]
