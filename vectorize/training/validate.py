"""Accuracy of an exported model on freshly generated crops, measured with onnxruntime.

    onestroke validate-classifier --seed 1000 --count 5000
"""

from __future__ import annotations

import os

import numpy as np

from vectorize.training.synth import SUBTYPES, generate


def evaluate_onnx(model_path: str | os.PathLike, *, count: int, seed: int, workers: int = 1) -> dict:
    """Overall, per-class and per-sub-type accuracy with 8-fold test-time augmentation."""
    from vectorize.junctions.cnn_classifier import CnnClassifier

    data = generate(count, seed=seed, workers=workers)
    classifier = CnnClassifier(model_path, check_hash=False)
    probability, _ = classifier.predict_crops(data.x.astype(np.float32) / 255.0)
    predicted = (probability >= 0.5).astype(np.int64)
    right = predicted == data.label

    def share(mask: np.ndarray) -> dict:
        return {"n": int(mask.sum()), "accuracy": round(float(right[mask].mean()) if mask.any() else 0.0, 4)}

    return {
        "seed": seed,
        "n": int(count),
        "accuracy": round(float(right.mean()), 4),
        "per_class": {"crossing": share(data.label == 1), "touching": share(data.label == 0)},
        "per_subtype": {name: share(data.subtype == i) for i, name in enumerate(SUBTYPES)},
    }
