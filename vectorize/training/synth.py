"""Synthetic crossings and touchings of two curves, cropped as the vectorizer crops them.

Each sample is a small raster image of two strokes meeting at one point, rendered in
working-image pixels (anti-aliased, pen or pencil, blur, noise, paper texture, ink blobs,
distractor strokes), then passed through the inference crop (`crop_junctions`) with a
junction centre and a stroke-width estimate jittered the way the medial-axis graph
jitters them. Labels: 1 = crossing, 0 = touching.

Curves are defined by their curvature along arc length (a smooth, decaying profile, so
that a strongly bent curve turns through at most ~130 degrees instead of spiralling),
which covers the cubic Bézier strokes of the paper (Fig. 6) and the gentler arcs of real
drawings.

Sub-types (`SUBTYPES`): shallow crossing (< 15 degrees), steep crossing, exact touch
(centrelines meet, |gap| <= 0.15 w) and near touch (gap 0.15-0.9 w: the inks still merge).
Shapes of handwriting across the sub-types (`SHAPES`): a steep crossing of one stroke with
itself after a tight loop (a cursive e, l or y), a steep crossing where one stroke bends
sharply right at the crossing (a cursive e's way in bending into its loop), and a branch
that ends 3-6 w past the junction (a cursive y's exit ending just past its loop).
"""

from __future__ import annotations

from dataclasses import dataclass
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from vectorize.junctions.junction_crop import CropSpec, crop_junctions

SUBTYPES = ("shallow_crossing", "steep_crossing", "exact_touch", "near_touch")
SHAPES = ("plain", "bent_crossing", "short_branch", "loop_crossing")  # a loop or bend wins over a short branch
CHUNK = 256  # samples per independently seeded chunk: output does not depend on workers


@dataclass(frozen=True)
class SynthSet:
    """A generated data set.

    x: (N, 2, S, S) uint8 crops (ink strength x 255); label: (N,) int64, 1 = crossing;
    subtype: (N,) int64 index into SUBTYPES; angle: (N,) crossing angle in degrees (0 for
    touchings); width: (N,) stroke width in render px; shape: (N,) int64 index into SHAPES;
    context: (N,) bool, the branches curl on into letters (cursive context).
    """

    x: np.ndarray
    label: np.ndarray
    subtype: np.ndarray
    angle: np.ndarray
    width: np.ndarray
    shape: np.ndarray
    context: np.ndarray


# ----------------------------------------------------------------------------- curves
def _curve(rng: np.random.Generator, origin: np.ndarray, heading: float, kappa0: float,
           w: float, step: float, ell: float | None = None) -> np.ndarray:
    """Points (M, 2) of a curve through `origin` with tangent angle `heading` there.

    Curvature along arc length s: (kappa0 + kappa1 s / l) exp(-(s / l)^2), integrated from
    s = 0 in both directions out to 30 w (beyond the far crop's corners); l is drawn from
    8-40 w unless `ell` (px) is given.
    """
    length = 30.0 * w
    s = np.arange(-length, length + step, step)
    ell = rng.uniform(8.0, 40.0) * w if ell is None else ell
    # Cap the total turning per side (|kappa0| l sqrt(pi) / 2) at ~130 degrees.
    if abs(kappa0) > 1e-9:
        ell = min(ell, 2.3 / (abs(kappa0) * np.sqrt(np.pi) / 2.0))
    kappa1 = rng.uniform(-0.3, 0.3) * abs(kappa0)
    kappa = (kappa0 + kappa1 * s / ell) * np.exp(-((s / ell) ** 2))
    i0 = len(s) // 2
    turn = np.cumsum(kappa) * step
    turn -= turn[i0]
    theta = heading + turn
    dx, dy = np.cos(theta) * step, np.sin(theta) * step
    x = np.cumsum(dx)
    y = np.cumsum(dy)
    return np.stack([x - x[i0], y - y[i0]], axis=1) + origin


# Shares of steep crossings made by one stroke crossing itself after a tight loop (a
# cursive e, l or y), and where one of two strokes bends sharply right at the crossing (a
# handwritten e's way in bending into its loop where the loop's side comes down across it).
LOOP_CROSSINGS = 0.3
BENT_CROSSINGS = 0.25
# Share of samples (either label) whose branches curl on into letters and whose far view
# holds more strokes, as in cursive words: the old model called half the crossings of the
# cursive benchmark touches with the whole word around them, but 94-98 % crossings with
# only 6-10 w of arc around each pass.
CURSIVE_CONTEXT = 0.35
# Per stroke: chance that one of its branches ends 3-6 w past the junction (a cursive y's
# exit ends ~5 w past its loop's crossing); the older cut keeps 6-21 w.
SHORT_BRANCHES = 0.07


def _bent_through(rng: np.random.Generator, a: float, w: float, step: float,
                  curves: list) -> tuple[list, float] | None:
    """`curves` (two strokes crossing at the origin at headings -a/2 and a/2, radians) with
    one of them replaced by a stroke that bends by 20-80 degrees within a few widths of the
    crossing (radius 3-10 w there, the bend centred up to 1.5 w before or after it), and
    the crossing angle (degrees) the bend leaves at the origin; None where the bent stroke
    meets the other one again in the far view or crosses it at less than 15 degrees."""
    side = int(rng.integers(2))
    turn = np.radians(rng.uniform(20.0, 80.0))
    radius = rng.uniform(3.0, 10.0) * w
    ell = turn * radius / np.sqrt(np.pi)  # total turning |kappa0| ell sqrt(pi) = turn
    kappa0 = rng.choice([-1.0, 1.0]) / radius
    bent = _curve(rng, np.zeros(2), a / 2 if side else -a / 2, kappa0, w, step, ell=ell)
    # The crossing (the origin) moves off the bend's middle by up to 1.5 w along the stroke.
    at = len(bent) // 2 + int(round(rng.uniform(-1.5, 1.5) * w / step))
    bent = bent - bent[at]
    tangent = bent[at + 1] - bent[at - 1]
    other = curves[1 - side]
    across = other[len(other) // 2 + 1] - other[len(other) // 2 - 1]
    cos = abs(np.dot(tangent, across)) / (np.linalg.norm(tangent) * np.linalg.norm(across))
    angle = float(np.degrees(np.arccos(np.clip(cos, 0.0, 1.0))))
    away = np.hypot(bent[:, 0], bent[:, 1]) > 4.0 * w
    if angle < 15.0 or np.any(cKDTree(other).query(bent[away])[0] < 1.5 * w):
        return None
    return ([bent, curves[1]] if side == 0 else [curves[0], bent]), angle


def _loop_crossing(rng: np.random.Generator, w: float, step: float) -> tuple[np.ndarray, int, int, float] | None:
    """One stroke (M, 2) px that crosses itself at the origin after a tight loop (a cursive
    e, l or y): its tangent turns by 210-330 degrees over a curvature bump 5-16 w wide.
    Returns the points, the indices of its first and second pass through the crossing and
    the crossing angle (degrees); None unless it crosses itself exactly once, at 15
    degrees or more, after a loop of at most 60 w, at least 10 w from either end, and its
    passes stay 1.5 w apart away from the crossing."""
    turn = np.radians(rng.uniform(210.0, 330.0))
    ell = rng.uniform(5.0, 16.0) * w
    k0 = rng.choice([-1.0, 1.0]) * turn / (ell * np.sqrt(np.pi))
    s = np.arange(-30.0 * w - 3.0 * ell, 30.0 * w + 3.0 * ell + step, step)
    k1 = rng.uniform(-0.5, 0.5) * abs(k0)  # an asymmetric loop: an e rather than an l
    k_slow = rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(1 / 400), np.log(1 / 15))) / w
    kappa = (k0 + k1 * s / ell) * np.exp(-((s / ell) ** 2)) + k_slow * np.exp(-((s / (20.0 * w)) ** 2))
    theta = np.cumsum(kappa) * step
    points = np.stack([np.cumsum(np.cos(theta)), np.cumsum(np.sin(theta))], axis=1) * step
    gap = int(4.0 * w / step)
    pairs = np.array(sorted(p for p in cKDTree(points).query_pairs(step, output_type="ndarray").tolist()
                            if p[1] - p[0] > gap)).reshape(-1, 2)
    if len(pairs) == 0 or np.any(np.abs(pairs[:, 0] - pairs[0, 0]) > gap):
        return None
    first, last = pairs[np.argmin(np.hypot(*(points[pairs[:, 0]] - points[pairs[:, 1]]).T))]
    if min(first, len(points) - 1 - last) * step < 10.0 * w:  # an end came back across the loop
        return None
    points = points - (points[first] + points[last]) / 2.0
    t1, t2 = points[first + 1] - points[first - 1], points[last + 1] - points[last - 1]
    angle = float(np.degrees(np.arccos(min(abs(t1 @ t2) / (np.linalg.norm(t1) * np.linalg.norm(t2)), 1.0))))
    away = np.flatnonzero(np.hypot(points[:, 0], points[:, 1]) > 4.0 * w)
    close = cKDTree(points[away]).query_pairs(1.5 * w, output_type="ndarray")
    apart = np.abs(away[close[:, 0]] - away[close[:, 1]]) > 4.5 * w / step  # folded back on itself
    if angle < 15.0 or (last - first) * step > 60.0 * w or np.any(apart):
        return None
    return points, int(first), int(last), angle


def _cursive_branches(rng: np.random.Generator, c: np.ndarray, passes: tuple[int, int], calm: float,
                      w: float, step: float, center: np.ndarray) -> np.ndarray:
    """Stroke `c` (M, 2) px, evenly spaced by `step`, with its branches curling on into
    letters beyond `calm` px of arc from the junction (`passes`: indices of its first and
    last pass there): curvature bumps of radius 1.5-6 w, 1.5-4 w wide, every 4-10 w, as
    the arches, loops and joins of cursive writing crowd the far view. The stroke is
    unchanged where a branch would come back within 2.5 w of the junction's `center`."""
    lo = max(passes[0] - int(calm / step), 1)
    hi = min(passes[1] + int(calm / step), len(c) - 2)
    heading = np.arctan2(*np.diff(c, axis=0).T[::-1])  # (M - 1,) of segment i -> i + 1
    arc = np.arange(len(c) - 1) * step
    out = c.copy()
    for side in (1, -1):
        start = hi if side > 0 else lo
        dist = side * (arc - arc[start])  # arc beyond the calm part, along the branch
        kappa = np.zeros_like(arc)
        at = rng.uniform(0.0, 4.0) * w
        while at < 30.0 * w:
            sigma = rng.uniform(1.5, 4.0) * w
            kappa += rng.choice([-1.0, 1.0]) / (rng.uniform(1.5, 6.0) * w) * np.exp(-0.5 * ((dist - at - sigma) / sigma) ** 2)
            at += rng.uniform(4.0, 10.0) * w
        kappa[dist < 0] = 0.0
        if side > 0:
            theta = heading + np.cumsum(kappa) * step
            for i in range(start + 1, len(c)):
                out[i] = out[i - 1] + step * np.array([np.cos(theta[i - 1]), np.sin(theta[i - 1])])
        else:
            theta = heading - np.cumsum(kappa[::-1])[::-1] * step
            for i in range(start - 1, -1, -1):
                out[i] = out[i + 1] - step * np.array([np.cos(theta[i]), np.sin(theta[i])])
    moved = np.r_[np.arange(lo), np.arange(hi + 1, len(c))]
    if len(moved) and np.min(np.hypot(*(out[moved] - center).T)) < 2.5 * w:
        return c
    return out


def _cut_branch(rng: np.random.Generator, c: np.ndarray, widths: np.ndarray, passes: tuple[int, int],
                reach: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Stroke `c` (M, 2) px and its `widths` (M,) with its first or last branch ending
    `reach` px past the junction (`passes`: indices of its first and last pass there)."""
    keep = int(round(reach / step))
    if rng.random() < 0.5:
        return c[:passes[1] + keep], widths[:passes[1] + keep]
    start = max(passes[0] - keep, 0)
    return c[start:], widths[start:]


def _rotate(points: np.ndarray, phi: float) -> np.ndarray:
    c, s = np.cos(phi), np.sin(phi)
    return points @ np.array([[c, s], [-s, c]])


# ---------------------------------------------------------------------------- render
def _coverage(points: np.ndarray, widths: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Anti-aliased ink coverage in [0, 1] of a variable-width polyline (dense points)."""
    h, wd = shape
    r = int(np.ceil(widths.max() / 2.0 + 1.0))
    keep = ((points[:, 0] > -r) & (points[:, 0] < wd + r) & (points[:, 1] > -r)
            & (points[:, 1] < h + r))
    points, widths = points[keep], widths[keep]
    cov = np.zeros(h * wd, dtype=np.float32)
    if len(points) == 0:
        return cov.reshape(h, wd)
    base = np.floor(points).astype(np.int64)
    off = np.arange(-r, r + 2)
    ox, oy = np.meshgrid(off, off)
    px = base[:, 0, None] + ox.ravel()[None, :]
    py = base[:, 1, None] + oy.ravel()[None, :]
    # Pixel (i, j) covers [j, j + 1) x [i, i + 1); its centre is at (j + 0.5, i + 0.5).
    d = np.hypot(px + 0.5 - points[:, 0, None], py + 0.5 - points[:, 1, None])
    c = np.clip(widths[:, None] / 2.0 - d + 0.5, 0.0, 1.0)
    ok = (c > 0) & (px >= 0) & (px < wd) & (py >= 0) & (py < h)
    np.maximum.at(cov, (py[ok] * wd + px[ok]), c[ok].astype(np.float32))
    return cov.reshape(h, wd)


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, int], sigma: float) -> np.ndarray:
    """Zero-mean, unit-std noise with correlation length ~sigma px."""
    n = ndimage.gaussian_filter(rng.standard_normal(shape).astype(np.float32), sigma)
    return n / max(float(n.std()), 1e-6)


def _render_sample(rng: np.random.Generator, spec: CropSpec) -> tuple[np.ndarray, int, int, float, float, int, bool]:
    """One sample: (crop (2, S, S) float32, label, subtype, angle_deg, width_px, shape, context)."""
    w = float(np.exp(rng.uniform(np.log(1.8), np.log(5.0))))
    half = int(np.ceil(0.5 * spec.far_span * np.sqrt(2.0) * w * 1.2 + 3.0))
    size = 2 * half + 1
    shape = (size, size)
    center = np.array([half + 0.5, half + 0.5]) + rng.uniform(-0.5, 0.5, 2)
    step = 0.3
    phi = rng.uniform(0.0, 2.0 * np.pi)
    crossing = rng.random() < 0.5
    shallow = False
    form = 0  # index into SHAPES
    passes = None  # per stroke: indices of its first and last pass through the junction
    if crossing:
        shallow = rng.random() < 0.45
        angle = rng.uniform(3.0, 15.0) if shallow else rng.uniform(15.0, 90.0)
        subtype = 0 if shallow else 1
        a = np.radians(angle)
        k = np.array([rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(1 / 400), np.log(1 / 10))) / w
                      for _ in range(2)])
        # Keep the second crossing of the two curves (at s ~ -2 a / dk) outside the far
        # crop: nearly straight strokes are what make a shallow crossing.
        dk = abs(k[1] - k[0])
        limit = 2.0 * a / (26.0 * w)
        if dk > limit:
            k *= limit / dk
        curves = [_curve(rng, np.zeros(2), -a / 2, k[0], w, step),
                  _curve(rng, np.zeros(2), a / 2, k[1], w, step)]
        pick = rng.random()
        if not shallow and pick < LOOP_CROSSINGS:
            loop = _loop_crossing(rng, w, step)
            if loop is not None:
                curves, angle, form = [loop[0]], loop[3], 3
                passes = [loop[1:3]]
        elif not shallow and pick < LOOP_CROSSINGS + BENT_CROSSINGS:
            bent = _bent_through(rng, a, w, step, curves)
            if bent is not None:
                (curves, angle), form = bent, 1
        jitter = rng.normal(0.0, 0.25 * w, 2)
        norm = np.linalg.norm(jitter)
        if norm > 0.6 * w:
            jitter *= 0.6 * w / norm
        contact = 0.0
    else:
        exact = rng.random() < 0.5
        subtype = 2 if exact else 3
        angle = 0.0
        gap = (rng.uniform(-0.15, 0.15) if exact else rng.uniform(0.15, 0.9)) * w
        r_rel = np.exp(rng.uniform(np.log(2.5), np.log(60.0))) * w
        u = rng.uniform(-0.3, 1.3)  # share of the bending; outside [0, 1]: internal tangency
        k_rel = 1.0 / r_rel
        # Curve A above (y < 0) bends up (negative curvature in y-down frame turns left).
        curves = [_curve(rng, np.array([0.0, -gap / 2]), 0.0, -u * k_rel, w, step),
                  _curve(rng, np.array([0.0, gap / 2]), 0.0, (1.0 - u) * k_rel, w, step)]
        contact = np.sqrt(2.0 * max(w - gap, 0.1 * w) * r_rel)  # half-length of merged ink
        jitter = np.array([rng.uniform(-1.0, 1.0) * min(0.5 * contact, 3.0 * w),
                           rng.normal(0.0, 0.15 * w)])
    curves = [_rotate(c, phi) + center for c in curves]
    if passes is None:
        passes = [(int(np.argmin(np.hypot(*(c - center).T))),) * 2 for c in curves]
    context = rng.random() < CURSIVE_CONTEXT
    if context:
        calm = contact + rng.uniform(3.0, 8.0) * w
        curves = [_cursive_branches(rng, c, at, calm, w, step, center) for c, at in zip(curves, passes)]
    jitter = _rotate(jitter[None], phi)[0]

    # Stroke widths: per-stroke scale and slow pressure variation along the stroke.
    ink = np.zeros(shape, dtype=np.float32)
    pencil = rng.random() < 0.35
    trans = np.ones(shape, dtype=np.float32)
    for c, at in zip(curves, passes):
        scale = w * rng.uniform(0.85, 1.15)
        n = len(c)
        pressure = np.interp(np.arange(n), np.linspace(0, n - 1, 6), rng.uniform(-1, 1, 6))
        widths = scale * (1.0 + rng.uniform(0.0, 0.15) * pressure)
        end = rng.random()
        if end < 0.1:
            # One branch of this stroke ends inside the far view (the drawing's end is near).
            c, widths = _cut_branch(rng, c, widths, at, rng.uniform(6.0, 21.0) * w, step)
        elif end < 0.1 + SHORT_BRANCHES and not shallow:  # a shallow crossing's short branch shows no crossing
            c, widths = _cut_branch(rng, c, widths, at, rng.uniform(3.0, 6.0) * w, step)
            form = form or 2
        cov = _coverage(c, widths, shape)
        if pencil:
            trans *= 1.0 - cov * rng.uniform(0.45, 0.9)
        else:
            ink = np.maximum(ink, cov)
    if rng.random() < 0.15:
        # Ink blob where the pen slowed down at the contact.
        yy, xx = np.mgrid[0:size, 0:size] + 0.5
        rx, ry = rng.uniform(0.5, 1.1) * w, rng.uniform(0.45, 0.9) * w
        t = rng.uniform(0, np.pi)
        dxx, dyy = xx - center[0], yy - center[1]
        e = ((dxx * np.cos(t) + dyy * np.sin(t)) / rx) ** 2 + ((-dxx * np.sin(t) + dyy * np.cos(t)) / ry) ** 2
        blob = np.clip((1.0 - np.sqrt(e)) * min(rx, ry) + 0.5, 0.0, 1.0).astype(np.float32)
        ink = np.maximum(ink, blob) if not pencil else ink
        trans = trans * (1.0 - 0.8 * blob) if pencil else trans
    for _ in range(rng.choice([0, 0, 1, 2]) + (rng.choice([1, 2, 3]) if context else 0)):
        # Distractor: another part of the drawing passing through the far view.
        off = rng.uniform(3.5, 16.0) * w * rng.choice([-1.0, 1.0])
        head = rng.uniform(0, 2 * np.pi)
        normal = np.array([-np.sin(head), np.cos(head)])
        kd = rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(1 / 200), np.log(1 / 15))) / w
        dc = _curve(rng, normal * off + center, head, kd, w, step * 2)
        if np.min(np.linalg.norm(dc - center, axis=1)) < (2.0 if context else 3.0) * w:
            continue
        cov = _coverage(dc, np.full(len(dc), w * rng.uniform(0.85, 1.15)), shape)
        ink = np.maximum(ink, cov)
        trans *= 1.0 - (0.7 * cov if pencil else 0.0)

    paper = rng.uniform(0.82, 1.0)
    if pencil:
        grain = np.clip(1.0 - 0.35 * rng.uniform(0.3, 1.0) * _smooth_noise(rng, shape, rng.uniform(0.4, 1.0)), 0.2, 1.3)
        dark = 1.0 - np.clip((1.0 - trans) * grain, 0.0, 1.0)
        gray = paper * dark
    else:
        level = rng.uniform(0.0, 0.4)
        gray = paper - (paper - level) * ink
    gray = gray + 0.02 * rng.uniform(0, 1) * _smooth_noise(rng, shape, 8.0)  # paper texture
    sigma = rng.uniform(0.0, 0.9)
    if sigma > 0.15:
        gray = ndimage.gaussian_filter(gray, sigma)
    gray = gray + rng.normal(0.0, rng.uniform(0.0, 0.06), shape)
    gray = np.clip(gray, 0.0, 1.0)
    if rng.random() < 0.5:
        gray = np.round(gray * 255.0) / 255.0

    w_est = w * float(np.exp(rng.normal(0.0, 0.07)))
    # Rendering put pixel (i, j)'s centre at (j + 0.5, i + 0.5); the crop (like the medial
    # axis) puts it at (j, i).
    crop = crop_junctions(gray.astype(np.float32), (center + jitter - 0.5)[None], w_est, spec)[0]
    return crop, int(crossing), subtype, float(angle), w, form, bool(context)


def _chunk(args: tuple[int, int, int, CropSpec]) -> tuple[np.ndarray, ...]:
    seed, index, count, spec = args
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    xs, ys, st, an, wd, sh, cx = [], [], [], [], [], [], []
    for _ in range(count):
        crop, label, subtype, angle, w, shape, context = _render_sample(rng, spec)
        xs.append(np.round(crop * 255.0).astype(np.uint8))
        ys.append(label)
        st.append(subtype)
        an.append(angle)
        wd.append(w)
        sh.append(shape)
        cx.append(context)
    return (np.stack(xs), np.array(ys), np.array(st), np.array(an), np.array(wd), np.array(sh),
            np.array(cx, dtype=bool))


def seeded_chunks(make_chunk, n: int, chunk: int, *, seed: int, spec, workers: int) -> list:
    """make_chunk((seed, index, count, spec)) over chunks of `chunk` items: a chunk's seed is
    its own, so the parts do not depend on `workers` (processes used when > 1)."""
    jobs = [(seed, i, min(chunk, n - i * chunk), spec) for i in range((n + chunk - 1) // chunk)]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            return list(pool.map(make_chunk, jobs))
    return [make_chunk(j) for j in jobs]


def generate(n: int, *, seed: int, spec: CropSpec = CropSpec(), workers: int = 1) -> SynthSet:
    """`n` samples, half crossings and half touchings in expectation; seeded and
    independent of `workers` (each chunk of CHUNK samples has its own seed)."""
    parts = seeded_chunks(_chunk, n, CHUNK, seed=seed, spec=spec, workers=workers)
    x, y, st, an, wd, sh, cx = (np.concatenate([p[i] for p in parts]) for i in range(7))
    return SynthSet(x=x, label=y.astype(np.int64), subtype=st.astype(np.int64),
                    angle=an.astype(np.float64), width=wd.astype(np.float64), shape=sh.astype(np.int64), context=cx)
