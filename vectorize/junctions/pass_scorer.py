"""Pairing the six feet of a triple point by good continuation and the image.

Continuation alone (`vectorize.axis.clusters.straightest_pairs`) picks the three passes that
bend least, measured by the feet's chords a few widths out. Where the passes curve near
the point, or a chord is pulled aside by the neighbouring ink, the straightest reading is
not the drawn one. The pass scorer, a small CNN shipped as ``models/pass_cnn.onnx`` and
run with onnxruntime, looks at the ink around the node with one candidate pass drawn in
(`vectorize.junctions.pass_crop`) and gives the probability that the pen went straight through
along it. A pairing's score adds, over its three passes, the image's log-odds and the
continuation cost (1 + cos between the feet, 0 = straight), each weighted as fitted on
generated triple points (the model's metadata, "combine"): a conditional-logit model over
the 15 pairings. Where that model is unsure (its best pairing's posterior under one half)
continuation decides, as it does alone when no model is installed.
"""

from __future__ import annotations

import os
from itertools import combinations
from pathlib import Path

import numpy as np

from vectorize.axis.clusters import Pairs, matchings
from vectorize.junctions.pass_crop import PassCropSpec, crop_passes, mirror_copies

DEFAULT_MODEL = Path(__file__).parents[1] / "models" / "pass_cnn.onnx"
# Below this posterior probability of its best pairing the combined model is unsure.
UNSURE = 0.5
PAIRS = tuple(combinations(range(6), 2))  # the 15 candidate passes of a six-foot node
PAIRINGS = tuple(matchings(list(range(6))))  # the 15 ways to pair six feet
# Each pairing's passes as indices into PAIRS: (15, 3).
PAIRING_INDEX = np.array([[PAIRS.index(tuple(sorted(p))) for p in pairing] for pairing in PAIRINGS])


def continuation_cost(feet: np.ndarray) -> np.ndarray:
    """(15,) cost of each candidate pass of PAIRS: 1 + cos between the two feet (0 = straight)."""
    return np.array([1.0 + float(np.dot(feet[i], feet[j])) for i, j in PAIRS])


def best_pairing(pass_scores: np.ndarray) -> tuple[Pairs, np.ndarray]:
    """The pairing whose three passes' scores (higher = likelier) add up most, and every
    pairing's total: pass_scores (15,) over PAIRS -> (pairing, (15,) over PAIRINGS)."""
    totals = pass_scores[PAIRING_INDEX].sum(axis=1)
    return PAIRINGS[int(np.argmax(totals))], totals


def log_odds(p: np.ndarray) -> np.ndarray:
    p = np.clip(p, 1e-4, 1.0 - 1e-4)
    return np.log(p / (1.0 - p))


class PassScorer:
    """The shipped (or given) pass-scorer model; the onnxruntime session starts on first use."""

    def __init__(self, model_path: str | os.PathLike | None = None, *, check_hash: bool = True) -> None:
        from vectorize.junctions.cnn_classifier import model_meta

        self.model_path = Path(model_path) if model_path is not None else DEFAULT_MODEL
        self.meta = model_meta(self.model_path, check_hash=check_hash)
        self.spec = PassCropSpec(**self.meta["crop"]) if "crop" in self.meta else PassCropSpec()
        combine = self.meta.get("combine", {"image": 1.0, "continuation": -4.0})
        self.image_weight = float(combine["image"])
        self.continuation_weight = float(combine["continuation"])
        self._session = None

    def predict_crops(self, crops: np.ndarray) -> np.ndarray:
        """crops (N, 4, S, S) float32 -> (N,) p_pass, the mean over the 4 mirrored copies."""
        crops = np.asarray(crops, dtype=np.float32)
        if len(crops) == 0:
            return np.zeros(0)
        if self._session is None:
            from vectorize.junctions.cnn_classifier import onnx_session

            self._session = onnx_session(self.model_path, self.meta.get("sha256", ""))
        copies = mirror_copies(crops).reshape(4 * len(crops), *crops.shape[1:])
        p = self._session.run(["p_pass"], {"crops": copies})[0].reshape(4, len(crops))
        return p.astype(np.float64).mean(axis=0)

    def pass_probabilities(self, gray: np.ndarray, centers: np.ndarray, feet: list[np.ndarray],
                           stroke_width: float) -> np.ndarray:
        """(K, 15) p_pass over PAIRS for K nodes (centres (K, 2), feet: K arrays (6, 2)),
        all in one batched call."""
        if not feet:
            return np.zeros((0, len(PAIRS)))
        k = len(feet)
        a = np.concatenate([[f[i] for i, _ in PAIRS] for f in feet])
        b = np.concatenate([[f[j] for _, j in PAIRS] for f in feet])
        at = np.repeat(np.asarray(centers, dtype=float).reshape(k, 2), len(PAIRS), axis=0)
        crops = crop_passes(gray, at, a, b, stroke_width, self.spec)
        return self.predict_crops(crops).reshape(k, len(PAIRS))

    def pass_scores(self, p_pass: np.ndarray, feet: np.ndarray) -> np.ndarray:
        """(15,) combined score of each candidate pass: weighted image log-odds plus
        weighted continuation cost."""
        return self.image_weight * log_odds(p_pass) + self.continuation_weight * continuation_cost(feet)


def pair_feet(gray: np.ndarray, centers: np.ndarray, feet: list[np.ndarray], stroke_width: float,
              scorer: PassScorer | None) -> list[Pairs]:
    """The pairing of each six-foot node: by continuation and image with a scorer, by
    continuation alone without one. centers (K, 2) px; feet: K arrays (6, 2) of unit
    tangents leaving the node."""
    return [pick for pick, _ in scored_pairings(gray, centers, feet, stroke_width, scorer)]


def scored_pairings(gray: np.ndarray, centers: np.ndarray, feet: list[np.ndarray], stroke_width: float,
                    scorer: PassScorer | None) -> list[tuple[Pairs, np.ndarray | None]]:
    """Per node, (its pairing as `pair_feet` picks it, (15,) posterior over PAIRINGS of the
    combined model, or None without a scorer)."""
    if scorer is None:
        return [(best_pairing(-continuation_cost(f))[0], None) for f in feet]
    p = scorer.pass_probabilities(gray, centers, feet, stroke_width)
    result = []
    for i, f in enumerate(feet):
        pick, totals = best_pairing(scorer.pass_scores(p[i], f))
        # The model's own posterior of its pick (softmax over the 15 pairings): below one
        # half it is unsure, and continuation decides alone.
        posterior = np.exp(totals - totals.max())
        posterior /= posterior.sum()
        result.append((pick if posterior.max() >= UNSURE else best_pairing(-continuation_cost(f))[0], posterior))
    return result
