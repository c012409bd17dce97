"""Three passes through one point: the cluster becomes one node, paired by continuation and
the image (the shipped pass scorer, run through onnxruntime on real rendered scenes)."""

from __future__ import annotations

import fnmatch
import hashlib
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from vectorize.axis.clusters import merge_triple_points, straightest_pairs
from vectorize.axis.simplify import directions
from vectorize.front_stages import front_stages
from vectorize.junctions.pass_scorer import DEFAULT_MODEL, PAIRS, PassScorer, pair_feet
from vectorize.options import VectorizeOptions
from vectorize.pipeline import vectorize_image
from vectorize.stage_clock import StageClock
from vectorize.stroke import Stroke
from vectorize.training.pass_eval import node_truth, same_pairing
from vectorize.training.triple_synth import render_scene

ROOT = Path(__file__).resolve().parents[2]


def _nodes(scene):
    """The vectorizer's own stages on a scene: (ink, graph, triple-point nodes)."""
    image = np.round(scene.gray * 255.0).astype(np.uint8)
    ink, _, graph, *_ = front_stages(image, VectorizeOptions(), StageClock())
    return ink, graph, list(merge_triple_points(graph, stroke_width=ink.stroke_width))


def test_a_thin_triple_point_is_one_node_paired_as_drawn():
    # 2.5 px lines: the cluster's inner branches are longer than 1.5 estimated widths, but
    # the junctions' maximal discs overlap, so the four junctions are still one node.
    scene = render_scene(np.random.default_rng([9]), width=2.5)
    ink, graph, nodes = _nodes(scene)
    assert len(nodes) == 1 and graph.degree(nodes[0]) == 6
    assert np.linalg.norm(graph.positions[nodes[0]] - scene.center) < 2.0 * scene.width
    feet = directions(graph, nodes[0], 2.5 * ink.stroke_width)
    truth = node_truth(graph, nodes[0], scene, ink.stroke_width)
    assert truth is not None and same_pairing(straightest_pairs(feet)[0], truth)


def test_the_shipped_pass_scorer_ships_and_pairs_real_triple_points():
    files = [DEFAULT_MODEL, DEFAULT_MODEL.with_suffix(".json"), DEFAULT_MODEL.with_suffix(".md")]
    package_data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for path in files:
        name = path.relative_to(ROOT / "vectorize").as_posix()
        assert path.is_file() and any(fnmatch.fnmatch(name, p) for p in package_data["vectorize"]), name
    scorer = PassScorer()  # checks the file against its sha256
    top3 = combined = total = 0
    for seed in range(24):
        if total >= 5:
            break
        scene = render_scene(np.random.default_rng([100, seed]))
        ink, graph, nodes = _nodes(scene)
        for node in nodes:
            truth = node_truth(graph, node, scene, ink.stroke_width)
            if truth is None:
                continue
            feet = directions(graph, node, 2.5 * ink.stroke_width)
            p = scorer.pass_probabilities(ink.gray, graph.positions[node][None], [feet], ink.stroke_width)[0]
            assert p.shape == (15,) and np.all((p >= 0) & (p <= 1))
            true_index = {PAIRS.index(tuple(sorted(t))) for t in truth}
            top3 += int(set(np.argsort(p)[-3:].tolist()) == true_index)
            pick = pair_feet(ink.gray, graph.positions[node][None], [feet], ink.stroke_width, scorer)[0]
            combined += int(same_pairing(pick, truth))
            total += 1
    # The three true passes are the image's likeliest three of fifteen, and the combined
    # pairing is the drawn one, on (nearly) every node found.
    assert total >= 5 and top3 >= total - 1 and combined >= total - 1


def _ray(center: np.ndarray, degrees: float, length: float) -> np.ndarray:
    """The point `length` px from `center` at `degrees` (counter-clockwise on the page, y down)."""
    a = np.radians(degrees)
    return center + length * np.array([np.cos(a), -np.sin(a)])


def test_a_point_where_two_spikes_leave_a_crossing_line_is_one_stroke():
    """A line comes in from the left end A through P, runs round a wide loop and back through
    P at 60 degrees, drawing two spikes out and back from P on the way (at 115 and 295
    degrees: collinear) before it leaves for its end E. Six feet leave P's cluster, read as
    three passes crossing; the straightest pairing joins the two spikes, a pass from free end
    to free end, and four free feet round one loop leave no pairing that does not cut the
    line. Before, that pass was a stroke of its own: 2 strokes. Now P is left to route
    inspection: one stroke from A to E, each spike drawn twice."""
    from scipy.spatial import cKDTree

    from tests.drawings import render_polylines

    p = np.array([200.0, 200.0])
    a, r, f, e = _ray(p, 180, 150), _ray(p, 0, 120), _ray(p, 240, 120), _ray(p, 60, 150)
    t = np.linspace(0.0, 1.0, 60)[1:, None]
    c1, c2 = r + np.array([60.0, 150.0]), f + np.array([-40.0, 120.0])
    loop = (1 - t) ** 3 * r + 3 * (1 - t) ** 2 * t * c1 + 3 * (1 - t) * t ** 2 * c2 + t ** 3 * f
    line = np.vstack([a, p, r, loop, p, _ray(p, 115, 45), p, _ray(p, 295, 45), p, e])
    width = 6.0
    result = vectorize_image(render_polylines([line], width=width), VectorizeOptions(classifier="cnn"))
    assert result.report.strokes == 1, result.report.warnings
    stroke = result.drawing.strokes[0]
    assert {tuple(np.round(stroke.start / 10)), tuple(np.round(stroke.end / 10))} == \
        {tuple(np.round(a / 10)), tuple(np.round(e / 10))}
    drawn = float(np.linalg.norm(np.diff(line, axis=0), axis=1).sum())
    assert abs(stroke.length - drawn) < 0.02 * drawn  # each spike twice, nothing more
    gap, _ = cKDTree(stroke.sample_evenly(0.5)).query(Stroke.from_polyline(line).sample_evenly(1.0))
    assert gap.max() < width


@pytest.mark.slow
def test_pass_scorer_training_is_reproducible_from_its_seed():
    pytest.importorskip("torch")
    from vectorize.training.train_pass import train_pass

    first, _ = train_pass(seed=5, scenes=12, epochs=1, batch=64, lr=4e-3, workers=1)
    second, _ = train_pass(seed=5, scenes=12, epochs=1, batch=64, lr=4e-3, workers=1)
    other, _ = train_pass(seed=6, scenes=12, epochs=1, batch=64, lr=4e-3, workers=1)
    a, b, c = first.state_dict(), second.state_dict(), other.state_dict()
    assert all(np.array_equal(a[k].numpy(), b[k].numpy()) for k in a)
    assert not all(np.array_equal(a[k].numpy(), c[k].numpy()) for k in a)


@pytest.mark.slow
def test_train_pass_scorer_command_exports_a_model_onnxruntime_runs(tmp_path):
    pytest.importorskip("torch")
    from click.testing import CliRunner

    from fabrication.cli import main

    out = tmp_path / "tiny.onnx"
    result = CliRunner().invoke(main, ["train-pass-scorer", "--seed", "3", "--scenes", "16", "--epochs", "1",
                                       "--batch", "64", "--calibration", "8", "--validation", "8",
                                       "--workers", "1", "--out", str(out)])
    assert result.exit_code == 0, result.output
    figures = json.loads(result.stdout)
    assert set(figures["validation"]) >= {"continuation", "image", "combined", "pipeline_nodes"}
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["sha256"] == hashlib.sha256(out.read_bytes()).hexdigest()
    scorer = PassScorer(out)
    assert scorer.image_weight == meta["combine"]["image"]
    scene = render_scene(np.random.default_rng([9]))
    feet = np.array([[np.cos(a), np.sin(a)] for a in np.radians([0, 180, 60, 240, 120, 300])])
    p = scorer.pass_probabilities(scene.gray, scene.center[None], [feet], scene.width)
    assert p.shape == (1, 15) and np.all((p >= 0) & (p <= 1))
