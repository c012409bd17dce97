"""Synthetic triple points: three curves crossing near one spot, with their true passes.

Each scene is a small raster image of three strokes whose lines are at least 30 degrees
apart, crossing within a fraction of a width of one centre (a hand never hits one point
exactly), bent along their length (`synth._curve`'s curvature profiles, stronger here, so
that a pass's chord near the point can mislead continuation), some ending inside the view,
pen ink on paper with blur and noise. The six halves of the curves, from the centre
outward, are the feet; halves 2k and 2k + 1 make pass k.

From a scene come the training crops of the pass scorer: all 15 pairs of feet, each as
`crop_passes` cuts it from feet directions measured the way the vectorizer measures them
(the chord to the point 2.5 widths plus the cluster's reach along the foot, jittered),
label 1 for the three true passes, and each candidate's continuation cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from vectorize.junctions.pass_crop import PassCropSpec, crop_passes
from vectorize.junctions.pass_scorer import PAIRS
from vectorize.training.synth import _coverage, _curve, _smooth_noise, seeded_chunks

CHUNK = 64  # scenes per independently seeded chunk: output does not depend on workers


@dataclass(frozen=True)
class TripleScene:
    """gray: (H, W) float32, 1 = paper; center: (2,) the spot the passes cross, px with
    pixel centres at integers (the medial axis's frame); halves: six (M, 2) point arrays from
    near the centre outward (2k, 2k + 1: pass k); width: stroke width in px."""

    gray: np.ndarray
    center: np.ndarray
    halves: tuple[np.ndarray, ...]
    width: float


@dataclass(frozen=True)
class PassSet:
    """Generated pass crops: x (N, 4, S, S) uint8 (x 255); label (N,) int64, 1 = a true
    pass; cost (N,) continuation cost, 1 + cos between the candidate's feet (0 = straight);
    scene (N,) index of the scene; pair (N,) index into PAIRS."""

    x: np.ndarray
    label: np.ndarray
    cost: np.ndarray
    scene: np.ndarray
    pair: np.ndarray


def _headings(rng: np.random.Generator) -> np.ndarray:
    """Three line directions (rad) at least 30 degrees apart (mod 180)."""
    g1 = rng.uniform(30.0, 90.0)
    g2 = rng.uniform(30.0, 150.0 - g1)
    return np.radians(rng.uniform(0.0, 180.0) + np.array([0.0, g1, g1 + g2]))


def render_scene(rng: np.random.Generator, *, width: float | None = None) -> TripleScene:
    """One scene, drawn from `rng`; `width` fixes the stroke width (default 1.8-10 px)."""
    w = float(width) if width is not None else float(np.exp(rng.uniform(np.log(1.8), np.log(10.0))))
    half = int(np.ceil(0.5 * 24.0 * np.sqrt(2.0) * w * 1.15 + 3.0))
    size = 2 * half + 1
    shape = (size, size)
    center = np.array([half + 0.5, half + 0.5]) + rng.uniform(-0.5, 0.5, 2)
    step = 0.3
    ink = np.zeros(shape, dtype=np.float32)
    halves = []
    for heading in _headings(rng):
        # Where this pass crosses: within ~0.35 w of the common centre.
        origin = center + rng.normal(0.0, 0.18 * w, 2)
        kappa = rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(np.log(1 / 300), np.log(1 / 2.5))) / w
        curve = _curve(rng, origin, heading + rng.choice([0.0, np.pi]), kappa, w, step)
        mid = len(curve) // 2
        widths = w * rng.uniform(0.85, 1.15) * np.ones(len(curve))
        if rng.random() < 0.15:
            # The line ends inside the view on one side (its far end is near).
            keep = int(rng.uniform(4.0, 12.0) * w / step)
            if rng.random() < 0.5:
                curve, widths = curve[:mid + keep], widths[:mid + keep]
            else:
                curve, widths, mid = curve[mid - keep:], widths[mid - keep:], keep
        ink = np.maximum(ink, _coverage(curve, widths, shape))
        halves += [curve[mid::-1] - 0.5, curve[mid:] - 0.5]
    paper = rng.uniform(0.85, 1.0)
    gray = paper - (paper - rng.uniform(0.0, 0.35)) * ink
    gray = gray + 0.02 * rng.uniform(0, 1) * _smooth_noise(rng, shape, 8.0)
    sigma = rng.uniform(0.0, 0.8)
    if sigma > 0.15:
        gray = ndimage.gaussian_filter(gray, sigma)
    gray = np.clip(gray + rng.normal(0.0, rng.uniform(0.0, 0.05), shape), 0.0, 1.0)
    gray = np.round(gray * 255.0) / 255.0
    return TripleScene(gray=gray.astype(np.float32), center=center - 0.5, halves=tuple(halves), width=w)


def chord_direction(points: np.ndarray, start: np.ndarray, reach: float) -> np.ndarray:
    """Unit chord from `start` to the first of `points` at least `reach` px from it."""
    dist = np.linalg.norm(points - start, axis=1)
    k = int(np.argmax(dist >= reach)) if (dist >= reach).any() else len(points) - 1
    chord = points[k] - start
    return chord / max(float(np.linalg.norm(chord)), 1e-9)


def scene_feet(rng: np.random.Generator, scene: TripleScene) -> tuple[np.ndarray, np.ndarray]:
    """The node the vectorizer would see and its six feet directions, measured as it
    measures them (chord at 2.5 w plus the cluster's reach), jittered: (centre, (6, 2))."""
    w = scene.width
    node = scene.center + rng.normal(0.0, 0.25 * w, 2)
    reach = (2.5 + rng.uniform(0.3, 1.5)) * w
    feet = np.array([chord_direction(h, node, reach) for h in scene.halves])
    turn = np.radians(rng.normal(0.0, 3.0, 6))
    c, s = np.cos(turn), np.sin(turn)
    return node, np.stack([c * feet[:, 0] - s * feet[:, 1], s * feet[:, 0] + c * feet[:, 1]], axis=1)


def _chunk(args: tuple[int, int, int, PassCropSpec]) -> tuple[np.ndarray, ...]:
    seed, index, count, spec = args
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    xs, labels, costs, scenes, pairs = [], [], [], [], []
    for k in range(count):
        scene = render_scene(rng)
        node, feet = scene_feet(rng, scene)
        a = np.array([feet[i] for i, _ in PAIRS])
        b = np.array([feet[j] for _, j in PAIRS])
        w_est = scene.width * float(np.exp(rng.normal(0.0, 0.07)))
        crops = crop_passes(scene.gray, np.repeat(node[None], len(PAIRS), axis=0), a, b, w_est, spec)
        xs.append(np.round(crops * 255.0).astype(np.uint8))
        labels.append([int(i // 2 == j // 2) for i, j in PAIRS])
        costs.append(1.0 + np.sum(a * b, axis=1))
        scenes.append(np.full(len(PAIRS), index * CHUNK + k))
        pairs.append(np.arange(len(PAIRS)))
    return (np.concatenate(xs), np.concatenate(labels), np.concatenate(costs), np.concatenate(scenes),
            np.concatenate(pairs))


def generate_passes(scenes: int, *, seed: int, spec: PassCropSpec = PassCropSpec(), workers: int = 1) -> PassSet:
    """The 15 candidate passes of each of `scenes` scenes; seeded and independent of
    `workers` (each chunk of CHUNK scenes has its own seed)."""
    parts = seeded_chunks(_chunk, scenes, CHUNK, seed=seed, spec=spec, workers=workers)
    x, label, cost, scene, pair = (np.concatenate([p[i] for p in parts]) for i in range(5))
    return PassSet(x=x, label=label.astype(np.int64), cost=cost, scene=scene.astype(np.int64),
                   pair=pair.astype(np.int64))
