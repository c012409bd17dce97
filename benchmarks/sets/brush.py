"""Brush and broad-nib drawings: single-line shapes whose ink width changes 3x along the line.

Two kinds, both through the glyph rules and ground truth of benchmarks/sets/hershey.py (scaled to
the canvas, crossings, retraces, ambiguous junctions scored by the fair-retrace rule):

- brush-kana: kana written in one brush stroke (く し つ て の ひ へ ろ る ん そ フ レ ノ
  and 乙), pen paths drawn here in a 100-unit em from the shapes of the printed characters
  (smooth runs meeting in cusps, as benchmarks/sets/handwriting.py writes letters). The brush
  presses in (the width rises from a third of the full width over the first 8 % of the
  line), the pressure drifts slowly (+-15 %), and the stroke ends either in a sweep (harai:
  the width falls to a third over the last 20 %) or blunt (tome);
- brush-capital: capital letters of the single-line EMS and Hershey fonts written with a
  broad nib held at 25-45 degrees: the width is full across the nib and a third along it
  (w = W (1/3 + 2/3 |sin(heading - nib)|), smoothed over half a width), so every curve
  swells and thins like calligraphy.

The ground truth's `stroke_width` is the full width W (6-16 px), the one the rules and the
order tolerance use; meta "width_profile" holds the local width along the line (knot
fractions of the arc length, widths in px), which benchmarks/common/render.py draws and the ink
metrics measure the excursion against (half the LOCAL width + 1 px).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import ndimage

from benchmarks.sets.drawings import _hermite, _Waypoint
from benchmarks.metrics.ground_truth import GroundTruth
from benchmarks.sets.hershey import Glyph, glyph_ground_truth, load_glyphs

# Kana as pen paths, x right, y down, in a 100-unit em: runs of 3+ points are smooth curves
# through them, runs of 2 points straight lines; consecutive runs meet in a cusp.
KANA: dict[str, list[list[tuple[float, float]]]] = {
    "ku": [[(66, 8), (44, 30), (24, 50)], [(24, 50), (46, 72), (68, 92)]],
    "shi": [[(34, 8), (32, 48), (35, 76), (55, 90), (80, 76), (90, 60)]],
    "tsu": [[(8, 42), (45, 27), (80, 30), (92, 50), (76, 72), (46, 85), (34, 86)]],
    "te": [[(8, 28), (50, 24), (86, 14)], [(86, 14), (55, 32), (40, 55), (42, 78), (60, 90), (74, 92)]],
    "no": [[(52, 8), (49, 32), (40, 62), (27, 84), (13, 72), (11, 45), (28, 23), (58, 17), (84, 30), (90, 60),
            (74, 84), (52, 92)]],
    "hi": [[(10, 32), (33, 27)], [(33, 27), (21, 55), (29, 80), (50, 89), (68, 72), (75, 34)],
           [(75, 34), (81, 60), (94, 74)]],
    "he": [[(6, 62), (30, 34)], [(30, 34), (62, 60), (94, 84)]],
    "ro": [[(22, 16), (52, 14), (72, 10)], [(72, 10), (44, 42), (18, 64)],
           [(18, 64), (55, 45), (82, 55), (84, 78), (60, 93), (34, 90)]],
    "ru": [[(22, 14), (52, 12), (72, 8)], [(72, 8), (44, 40), (16, 62)],
           [(16, 62), (55, 44), (84, 54), (86, 76), (66, 90), (40, 90), (30, 78), (44, 70), (56, 80), (52, 97),
            (34, 100)]],
    "n": [[(56, 6), (20, 92)], [(20, 92), (40, 56), (56, 52), (60, 80), (72, 92), (94, 70)]],
    "so": [[(24, 12), (62, 8)], [(62, 8), (18, 42)], [(18, 42), (86, 34)],
           [(86, 34), (48, 55), (40, 80), (56, 93), (78, 90)]],
    "fu": [[(14, 18), (82, 16)], [(82, 16), (76, 55), (40, 92)]],
    "re": [[(30, 8), (30, 82)], [(30, 82), (62, 64), (90, 38)]],
    "no-kata": [[(72, 8), (56, 55), (14, 92)]],
    "otsu": [[(14, 14), (76, 14)], [(76, 14), (24, 70)], [(24, 70), (40, 88), (88, 88), (92, 70)]],
}
CAPITAL_FONTS = ("EMSReadabilityItalic", "EMSElfin", "EMSNixish", "EMSReadability", "HersheySans1", "EMSTech")
THIN = 1.0 / 3.0  # thinnest ink over the full width


def kana_glyph(name: str) -> Glyph:
    """A kana pen path as a one-move-to glyph (SVG path data, y up as in a font)."""
    controls = []
    for run in KANA[name]:
        piece, _ = _hermite([_Waypoint(np.array(p, dtype=float)) for p in run], closed=False)
        controls.append(piece.control)
    c = np.concatenate(controls) * np.array([1.0, -1.0])
    d = f"M {c[0, 0, 0]:.4f} {c[0, 0, 1]:.4f} " + " ".join(
        "C " + " ".join(f"{x:.4f} {y:.4f}" for x, y in seg[1:]) for seg in c)
    return Glyph("kana", name, name, d)


def brush_profile(rng: np.random.Generator, length: float, width: float) -> tuple[np.ndarray, np.ndarray]:
    """A brush's width along a line of `length` px (module doc): (knot fractions, widths px)."""
    f = np.linspace(0.0, 1.0, max(8, int(length / 2.0)))
    pressure = 1.0 + 0.15 * sum(rng.uniform(0.4, 1.0) * np.sin(2 * np.pi * f * rng.uniform(0.5, 2.5)
                                                                + rng.uniform(0, 2 * np.pi)) for _ in range(2)) / 2
    press_in = np.clip(f / 0.08, 0.0, 1.0)
    p = pressure * (THIN + (1 - THIN) * press_in)
    if rng.uniform() < 0.6:  # a sweep out (harai), else a blunt stop (tome)
        p *= THIN + (1 - THIN) * np.clip((1.0 - f) / 0.2, 0.0, 1.0)
    return f, width * np.clip(p, THIN, 1.0)


def nib_profile(stroke, width: float, nib: float) -> tuple[np.ndarray, np.ndarray]:
    """A broad nib's width along `stroke` (module doc), nib angle in radians."""
    n = max(8, int(stroke.length / 1.0))
    s = np.linspace(0.0, stroke.length, n)
    heading = stroke.tangents_at(stroke.parameters_at_lengths(s))
    angle = np.arctan2(heading[:, 1], heading[:, 0])
    w = width * (THIN + (1 - THIN) * np.abs(np.sin(angle - nib)))
    w = ndimage.gaussian_filter1d(w, sigma=max(1.0, width / 2), mode="nearest")
    return s / stroke.length, np.clip(w, THIN * width, width)


def _with_profile(gt: GroundTruth, kind: str, profile, prefix: str = "") -> GroundTruth:
    return replace(gt, name=f"{prefix}{gt.name}", kind=kind, meta={**gt.meta, "width_profile": profile})


def kana_set(count: int, seed: int = 0) -> list[GroundTruth]:
    """`count` brush kana (the names in turn, widths and pressure seeded)."""
    out: list[GroundTruth] = []
    names = list(KANA)
    for k in range(len(names) * 3):
        if len(out) >= count:
            break
        name = names[(k + seed) % len(names)]
        rng = np.random.default_rng([seed, k, 41])
        width = float(np.round(rng.uniform(10.0, 36.0) * 4) / 4)
        glyph = kana_glyph(name)
        gt = (glyph_ground_truth(glyph, width, close_gaps=True, fit=rng.uniform(0.6, 1.0))
              or glyph_ground_truth(glyph, width, ambiguous=True, close_gaps=True, fit=rng.uniform(0.6, 1.0)))
        if gt is not None:
            out.append(_with_profile(replace(gt, name=f"{gt.name}-{k}"), "brush-kana",
                                     brush_profile(rng, gt.stroke.length, width)))
    return out


def capital_set(count: int, seed: int = 0) -> list[GroundTruth]:
    """`count` broad-nib capitals (fonts in turn, letters seeded)."""
    glyphs = [g for g in load_glyphs() if g.font in CAPITAL_FONTS and len(g.unicode) == 1 and "A" <= g.unicode <= "Z"]
    rng = np.random.default_rng([seed, 43])
    order = rng.permutation(len(glyphs))
    out: list[GroundTruth] = []
    letters: set[str] = set()
    for k in order:
        g = glyphs[k]
        if len(out) >= count:
            break
        if g.unicode in letters and len(letters) < 26:
            continue
        grng = np.random.default_rng([seed, int(k), 47])
        width = float(np.round(grng.uniform(8.0, 24.0) * 4) / 4)
        fit = grng.uniform(0.6, 1.0)
        gt = (glyph_ground_truth(g, width, close_gaps=True, fit=fit)
              or glyph_ground_truth(g, width, ambiguous=True, close_gaps=True, fit=fit))
        if gt is None:
            continue
        letters.add(g.unicode)
        nib = np.radians(grng.uniform(25.0, 45.0))
        out.append(_with_profile(gt, "brush-capital", nib_profile(gt.stroke, width, -nib), "capital-"))
    return out
