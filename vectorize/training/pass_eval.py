"""Pairing accuracy at triple points: continuation alone, the image alone, and both.

Two measures on fresh scenes (`vectorize.training.triple_synth`, never benchmark drawings):

- synthetic: the six feet measured from the true curves the way the vectorizer measures
  them; the truth is known by construction;
- pipeline: the scene goes through the vectorizer's own stages (binarize, outline, medial
  axis, pruning, `merge_triple_points`), and each six-foot node found is paired; a foot's
  truth is the curve half its branch runs along.

Also fits the combination weights (`fit_combination`). Needs numpy, scipy and
onnxruntime only.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy.optimize import minimize
from scipy.special import logsumexp

from vectorize.axis.clusters import Pairs, merge_triple_points, straightest_pairs
from vectorize.axis.simplify import directions, slot_points, slots
from vectorize.junctions.pass_scorer import PAIRING_INDEX, PAIRS, PassScorer, best_pairing, log_odds
from vectorize.training.triple_synth import TripleScene, generate_passes, render_scene

METHODS = ("continuation", "image", "combined")
RIDGE = 1e-3


def _synthetic(model_path: str | os.PathLike, scenes: int, seed: int, workers: int):
    """(image log-odds (S, 15), continuation cost (S, 15)) over PAIRS; pairing 0 is true."""
    data = generate_passes(scenes, seed=seed, workers=workers)
    p = PassScorer(model_path, check_hash=False).predict_crops(data.x.astype(np.float32) / 255.0)
    return log_odds(p).reshape(scenes, len(PAIRS)), data.cost.reshape(scenes, len(PAIRS))


def fit_combination(model_path: str | os.PathLike, *, scenes: int, seed: int, workers: int = 1) -> dict:
    """Weights of image log-odds (>= 0) and continuation cost (<= 0) that maximise the
    likelihood of the true pairing among the 15 (conditional logit) on `scenes` fresh scenes."""
    logit, cost = _synthetic(model_path, scenes, seed, workers)
    features = np.stack([logit[:, PAIRING_INDEX].sum(axis=2), cost[:, PAIRING_INDEX].sum(axis=2)], axis=-1)

    def loss(weights: np.ndarray) -> float:
        totals = features @ weights  # (S, 15 pairings)
        # A little ridge keeps the weights finite where the scenes are all told apart.
        return float(np.mean(logsumexp(totals, axis=1) - totals[:, 0]) + RIDGE * weights @ weights)

    # Signs fixed: the image's log-odds never count against a pass, nor does straightness.
    found = minimize(loss, np.array([1.0, -1.0]), method="L-BFGS-B", bounds=[(0.0, None), (None, 0.0)])
    return {"image": round(float(found.x[0]), 4), "continuation": round(float(found.x[1]), 4),
            "scenes": scenes, "seed": seed}


def node_truth(graph, node: int, scene: TripleScene, stroke_width: float) -> Pairs | None:
    """The drawn pairing of a node's six feet (slot indices): each foot belongs to the pass
    whose curve half lies nearest to the foot's point 3 widths out; None unless every pass
    gets exactly two feet."""
    label = []
    for s in slots(graph, node):
        pts = slot_points(graph, s)
        dist = np.linalg.norm(pts - graph.positions[node], axis=1)
        far = np.flatnonzero(dist > 3.0 * stroke_width)
        probe = pts[far[0] if len(far) else -1]
        label.append(int(np.argmin([np.min(np.linalg.norm(h - probe, axis=1)) for h in scene.halves])) // 2)
    if sorted(label) != [0, 0, 1, 1, 2, 2]:
        return None
    return tuple(tuple(i for i in range(6) if label[i] == k) for k in range(3))


def same_pairing(a: Pairs, b: Pairs) -> bool:
    """Whether two pairings of the same feet are equal, whatever the order of pairs and feet."""
    return {frozenset(p) for p in a} == {frozenset(p) for p in b}


def _pipeline_chunk(args: tuple[str, int, int, int]) -> list[tuple[bool, bool, bool]]:
    """Run the vectorizer's stages on scenes start..stop-1; per labelled node: right or
    wrong for each method."""
    from vectorize.front_stages import front_stages
    from vectorize.options import VectorizeOptions
    from vectorize.stage_clock import StageClock

    model_path, seed, start, stop = args
    scorer = PassScorer(model_path, check_hash=False)
    results = []
    for index in range(start, stop):
        scene = render_scene(np.random.default_rng([seed, index]))
        image = np.round(scene.gray * 255.0).astype(np.uint8)
        ink, _, graph, *_ = front_stages(image, VectorizeOptions(), StageClock())
        w = ink.stroke_width
        for node in merge_triple_points(graph, stroke_width=w):
            feet = directions(graph, node, 2.5 * w)
            if len(feet) != 6:
                continue
            truth = node_truth(graph, node, scene, w)
            if truth is None:
                continue  # a foot that follows no curve half: no truth to judge by
            p = scorer.pass_probabilities(ink.gray, graph.positions[node][None], [feet], w)[0]
            picks = (straightest_pairs(feet)[0], best_pairing(log_odds(p))[0],
                     best_pairing(scorer.pass_scores(p, feet))[0])
            results.append(tuple(same_pairing(pick, truth) for pick in picks))
    return results


def evaluate_pairing(model_path: str | os.PathLike, *, scenes: int, seed: int, workers: int = 1) -> dict:
    """Pairing accuracy of each method on `scenes` fresh scenes, synthetic and pipeline."""
    scorer = PassScorer(model_path, check_hash=False)
    logit, cost = _synthetic(model_path, scenes, seed, workers)
    picks = {"continuation": (-cost)[:, PAIRING_INDEX].sum(axis=2).argmax(axis=1),
             "image": logit[:, PAIRING_INDEX].sum(axis=2).argmax(axis=1),
             "combined": (scorer.image_weight * logit + scorer.continuation_weight * cost)[:, PAIRING_INDEX]
             .sum(axis=2).argmax(axis=1)}
    step = 25
    jobs = [(str(model_path), seed, i, min(i + step, scenes)) for i in range(0, scenes, step)]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            parts = list(pool.map(_pipeline_chunk, jobs))
    else:
        parts = [_pipeline_chunk(j) for j in jobs]
    nodes = np.array([r for part in parts for r in part], dtype=bool).reshape(-1, 3)
    result = {"seed": seed, "synthetic_scenes": scenes, "pipeline_scenes": scenes, "pipeline_nodes": len(nodes)}
    for k, method in enumerate(METHODS):
        result[method] = {"synthetic": round(float(np.mean(picks[method] == 0)), 4),
                          "pipeline": round(float(nodes[:, k].mean()) if len(nodes) else 0.0, 4)}
    return result
