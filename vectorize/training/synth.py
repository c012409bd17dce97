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
"""

from __future__ import annotations

from dataclasses import dataclass
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import ndimage

from vectorize.junctions.junction_crop import CropSpec, crop_junctions

SUBTYPES = ("shallow_crossing", "steep_crossing", "exact_touch", "near_touch")
CHUNK = 256  # samples per independently seeded chunk: output does not depend on workers


@dataclass(frozen=True)
class SynthSet:
    """A generated data set.

    x: (N, 2, S, S) uint8 crops (ink strength x 255); label: (N,) int64, 1 = crossing;
    subtype: (N,) int64 index into SUBTYPES; angle: (N,) crossing angle in degrees (0 for
    touchings); width: (N,) stroke width in render px.
    """

    x: np.ndarray
    label: np.ndarray
    subtype: np.ndarray
    angle: np.ndarray
    width: np.ndarray


# ----------------------------------------------------------------------------- curves
def _curve(rng: np.random.Generator, origin: np.ndarray, heading: float, kappa0: float,
           w: float, step: float) -> np.ndarray:
    """Points (M, 2) of a curve through `origin` with tangent angle `heading` there.

    Curvature along arc length s: (kappa0 + kappa1 s / l) exp(-(s / l)^2), integrated from
    s = 0 in both directions out to 30 w (beyond the far crop's corners).
    """
    length = 30.0 * w
    s = np.arange(-length, length + step, step)
    ell = rng.uniform(8.0, 40.0) * w
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


def _render_sample(rng: np.random.Generator, spec: CropSpec) -> tuple[np.ndarray, int, int, float, float]:
    """One sample: (crop (2, S, S) float32, label, subtype, angle_deg, width_px)."""
    w = float(np.exp(rng.uniform(np.log(1.8), np.log(5.0))))
    half = int(np.ceil(0.5 * spec.far_span * np.sqrt(2.0) * w * 1.2 + 3.0))
    size = 2 * half + 1
    shape = (size, size)
    center = np.array([half + 0.5, half + 0.5]) + rng.uniform(-0.5, 0.5, 2)
    step = 0.3
    phi = rng.uniform(0.0, 2.0 * np.pi)
    crossing = rng.random() < 0.5
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
    jitter = _rotate(jitter[None], phi)[0]

    # Stroke widths: per-stroke scale and slow pressure variation along the stroke.
    ink = np.zeros(shape, dtype=np.float32)
    pencil = rng.random() < 0.35
    trans = np.ones(shape, dtype=np.float32)
    for c in curves:
        scale = w * rng.uniform(0.85, 1.15)
        n = len(c)
        pressure = np.interp(np.arange(n), np.linspace(0, n - 1, 6), rng.uniform(-1, 1, 6))
        widths = scale * (1.0 + rng.uniform(0.0, 0.15) * pressure)
        if rng.random() < 0.1:
            # One branch of this stroke ends inside the far view (the drawing's end is near).
            cut = int(rng.uniform(0.6, 0.85) * n)  # branch keeps 6-21 w
            c, widths = (c[:cut], widths[:cut]) if rng.random() < 0.5 else (c[-cut:], widths[-cut:])
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
    for _ in range(rng.choice([0, 0, 1, 2])):
        # Distractor: another part of the drawing passing through the far view.
        off = rng.uniform(3.5, 16.0) * w * rng.choice([-1.0, 1.0])
        head = rng.uniform(0, 2 * np.pi)
        normal = np.array([-np.sin(head), np.cos(head)])
        kd = rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(1 / 200), np.log(1 / 15))) / w
        dc = _curve(rng, normal * off + center, head, kd, w, step * 2)
        if np.min(np.linalg.norm(dc - center, axis=1)) < 3.0 * w:
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
    return crop, int(crossing), subtype, float(angle), w


def _chunk(args: tuple[int, int, int, CropSpec]) -> tuple[np.ndarray, ...]:
    seed, index, count, spec = args
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    xs, ys, st, an, wd = [], [], [], [], []
    for _ in range(count):
        crop, label, subtype, angle, w = _render_sample(rng, spec)
        xs.append(np.round(crop * 255.0).astype(np.uint8))
        ys.append(label)
        st.append(subtype)
        an.append(angle)
        wd.append(w)
    return np.stack(xs), np.array(ys), np.array(st), np.array(an), np.array(wd)


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
    x, y, st, an, wd = (np.concatenate([p[i] for p in parts]) for i in range(5))
    return SynthSet(x=x, label=y.astype(np.int64), subtype=st.astype(np.int64),
                    angle=an.astype(np.float64), width=wd.astype(np.float64))
