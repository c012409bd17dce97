"""The shipped crossing-vs-touching CNN: integrity, accuracy, determinism, no torch at run time."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys

import numpy as np
import pytest

from vectorize.junctions.cnn_classifier import DEFAULT_MODEL, CnnClassifier
from vectorize.junctions.intersections import Junction
from vectorize.junctions.junction_crop import dihedral_copies
from vectorize.training.synth import generate


def test_shipped_model_matches_its_card():
    meta = json.loads(DEFAULT_MODEL.with_suffix(".json").read_text())
    digest = hashlib.sha256(DEFAULT_MODEL.read_bytes()).hexdigest()
    assert digest == meta["sha256"]
    assert digest in DEFAULT_MODEL.with_suffix(".md").read_text()
    assert DEFAULT_MODEL.stat().st_size < 5_000_000
    assert meta["validation"]["n"] >= 5000
    CnnClassifier()  # checks the hash itself


def test_a_damaged_model_is_refused(tmp_path):
    from onestroke.errors import VectorizeError

    broken = tmp_path / "crossing_cnn.onnx"
    broken.write_bytes(DEFAULT_MODEL.read_bytes()[:-10] + b"0123456789")
    (tmp_path / "crossing_cnn.json").write_text(DEFAULT_MODEL.with_suffix(".json").read_text())
    with pytest.raises(VectorizeError, match="sha256"):
        CnnClassifier(broken)


def test_accuracy_on_fresh_crops():
    data = generate(500, seed=4242)
    p, share = CnnClassifier().predict_crops(data.x.astype(np.float32) / 255.0)
    accuracy = float(((p >= 0.5) == data.label).mean())
    assert accuracy >= 0.95, accuracy
    assert np.all((share >= 0.5) & (share <= 1.0))


def test_test_time_augmentation_makes_the_answer_rotation_invariant():
    data = generate(8, seed=7)
    crops = data.x.astype(np.float32) / 255.0
    classifier = CnnClassifier()
    p, _ = classifier.predict_crops(crops)
    for copy in dihedral_copies(crops)[1:]:
        q, _ = classifier.predict_crops(copy)
        assert np.allclose(p, q, atol=1e-5)


def test_classify_is_deterministic_on_a_drawing():
    from tests.drawings import figure_eight, render_polylines

    gray = render_polylines([figure_eight()]).astype(np.float32) / 255.0
    directions = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    junction = Junction(center=np.array([200.0, 200.0]), directions=directions, width=6.0)
    first = CnnClassifier().classify(gray, [junction], 6.0)
    second = CnnClassifier().classify(gray, [junction], 6.0)
    assert first == second
    assert first[0].is_crossing and first[0].confidence >= 0.75


def test_a_vectorize_run_never_imports_torch(tmp_path):
    code = (
        "import sys, numpy as np\n"
        "from tests.drawings import figure_eight, render_polylines\n"
        "from vectorize import vectorize_image, VectorizeOptions\n"
        "r = vectorize_image(render_polylines([figure_eight()]), VectorizeOptions(classifier='cnn'))\n"
        "assert r.report.intersections == 1, r.report\n"
        "assert 'torch' not in sys.modules, 'torch was imported'\n"
        "print('ok')\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=str(
        __import__("pathlib").Path(__file__).parents[2]))
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


def test_training_smoke_run(tmp_path, monkeypatch):
    """Also issue 14 item 7: without --out the model goes to ./crossing_cnn.onnx (+ .json,
    .md) in the current folder, and the shipped model is not touched."""
    pytest.importorskip("torch")
    from click.testing import CliRunner

    from fabrication.cli import main
    from vectorize.junctions.cnn_classifier import DEFAULT_MODEL

    shipped = DEFAULT_MODEL.read_bytes()
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["train-classifier", "--seed", "3", "--samples", "256", "--epochs", "1",
                                       "--batch", "64", "--validation", "128", "--workers", "1"])
    assert result.exit_code == 0, result.output
    out = tmp_path / "crossing_cnn.onnx"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crossing_cnn.json", "crossing_cnn.md", "crossing_cnn.onnx"]
    assert DEFAULT_MODEL.read_bytes() == shipped
    assert json.loads(result.stdout)["n"] == 128
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["sha256"] == hashlib.sha256(out.read_bytes()).hexdigest()
    assert meta["validation"]["n"] == 128
    p, _ = CnnClassifier(out).predict_crops(generate(16, seed=9).x.astype(np.float32) / 255.0)
    assert p.shape == (16,) and np.all((p >= 0) & (p <= 1))
