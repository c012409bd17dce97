"""Three passes through one point: the cluster becomes one node, paired by continuation and
the image (the shipped pass scorer, run through onnxruntime on real rendered scenes)."""

from __future__ import annotations

import numpy as np
import pytest

from vectorize.clusters import merge_triple_points, straightest_pairs
from vectorize.options import VectorizeOptions
from vectorize.simplify import directions
from vectorize.training.pass_eval import node_truth, same_pairing
from vectorize.training.triple_synth import render_scene
from vectorize.vectorizer import _Clock, _front

def _nodes(scene):
    """The vectorizer's own stages on a scene: (ink, graph, triple-point nodes)."""
    image = np.round(scene.gray * 255.0).astype(np.uint8)
    ink, _, graph, _, _ = _front(image, VectorizeOptions(), _Clock())
    return ink, graph, list(merge_triple_points(graph, stroke_width=ink.stroke_width))


def test_a_thin_triple_point_is_one_node_paired_as_drawn():
    # 2.5 px lines: the cluster's inner branches are longer than 1.5 estimated widths, but
    # the junctions' maximal discs overlap, so the four junctions are still one node.
    scene = render_scene(np.random.default_rng([3]), width=2.5)
    ink, graph, nodes = _nodes(scene)
    assert len(nodes) == 1 and graph.degree(nodes[0]) == 6
    assert np.linalg.norm(graph.positions[nodes[0]] - scene.center) < 2.0 * scene.width
    feet = directions(graph, nodes[0], 2.5 * ink.stroke_width)
    truth = node_truth(graph, nodes[0], scene, ink.stroke_width)
    assert truth is not None and same_pairing(straightest_pairs(feet)[0], truth)
