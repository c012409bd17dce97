"""Both training commands write a model, its .json and its .md all together or not at all."""

from __future__ import annotations

import shutil

import pytest

from vectorize.junctions.cnn_classifier import DEFAULT_MODEL as CROSSING_MODEL, CnnClassifier
from vectorize.junctions.pass_scorer import DEFAULT_MODEL as PASS_MODEL, PassScorer


def _train_crossing_cnn(out, monkeypatch):
    from vectorize.training import train

    monkeypatch.setattr(train, "evaluate_onnx", _interrupted)  # the validation after export
    train.train_and_export(seed=3, samples=256, epochs=1, batch=64, validation=128, out=out)


def _train_pass_scorer(out, monkeypatch):
    from vectorize.training import train_pass

    monkeypatch.setattr(train_pass, "evaluate_pairing", _interrupted)  # after calibration
    train_pass.train_and_export_pass(seed=3, scenes=12, epochs=1, batch=64, calibration=8, validation=8, out=out)


def _interrupted(*args, **kwargs):
    raise KeyboardInterrupt


@pytest.mark.parametrize("shipped, train, load", [(CROSSING_MODEL, _train_crossing_cnn, CnnClassifier),
                                                  (PASS_MODEL, _train_pass_scorer, PassScorer)],
                         ids=["train-classifier", "train-pass-scorer"])
def test_an_interrupted_training_leaves_the_old_model_and_its_metadata(tmp_path, monkeypatch, shipped, train, load):
    """A Ctrl-C in the validation after export used to leave the new .onnx beside the old
    .json, a pair the vectorizer refuses as damaged. Now the old trio stays byte for byte and
    no temporary file is left."""
    pytest.importorskip("torch")
    out = tmp_path / shipped.name
    for suffix in (".onnx", ".json", ".md"):
        shutil.copy(shipped.with_suffix(suffix), out.with_suffix(suffix))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(KeyboardInterrupt):
        train(out, monkeypatch)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    load(out)  # model and metadata still agree
