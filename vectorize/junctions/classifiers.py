"""The crossing classifiers by name: the factory beside the pipeline that calls it.

`vectorize.junctions.intersections` holds the junction types and the geometric rule, and
`vectorize.junctions.cnn_classifier` the network; this module imports both, so neither imports the
other back.
"""

from __future__ import annotations

import functools

from onestroke.errors import InputError
from vectorize.junctions.intersections import GeometricClassifier, IntersectionClassifier


def make_classifier(name: str | IntersectionClassifier) -> IntersectionClassifier:
    """The classifier called `name`: "cnn" (shipped ONNX model) or "geometric"; a classifier
    object (`VectorizeOptions.classifier` may hold one) is returned as it is."""
    if not isinstance(name, str):
        return name
    return _named(name)


@functools.lru_cache(maxsize=None)
def _named(name: str) -> IntersectionClassifier:
    """Cached: loading and hash-checking the model and starting onnxruntime cost more than
    classifying a drawing, and the classifiers hold no state that a run changes."""
    if name == "geometric":
        return GeometricClassifier()
    if name == "cnn":
        from vectorize.junctions.cnn_classifier import CnnClassifier

        return CnnClassifier()
    raise InputError(f"unknown classifier {name!r}; use 'cnn' or 'geometric'")


@functools.lru_cache(maxsize=None)
def shipped_pass_scorer():
    """The shipped pass scorer of triple points (`vectorize.junctions.pass_scorer`), or None when its
    model is not installed: pairing then goes by continuation alone. Cached like the CNN;
    its onnxruntime session starts only when a drawing has a triple point."""
    from vectorize.junctions.pass_scorer import DEFAULT_MODEL, PassScorer

    return PassScorer() if DEFAULT_MODEL.is_file() else None
