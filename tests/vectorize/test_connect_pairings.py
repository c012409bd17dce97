"""Which junction's pairing is changed where the decided pairings cut the single line in
pieces (`vectorize.route.route_inspection.connect_pairings`)."""

from __future__ import annotations

import numpy as np
import pytest

from vectorize.axis.graph import Branch, MedialGraph
from vectorize.route.route_inspection import connect_pairings

# Slot pairs at a node whose four slots are the four branches below, in order.
APART = ((0, 1), (2, 3))  # two loops: branches 0-1 and 2-3
ACROSS = ((0, 2), (1, 3))
OTHER = ((0, 3), (1, 2))
CAPPED = (0.0, 4.05, 5.79)  # `vectorizer._pairing_costs` of a verdict at its cap, p 0.98


def _ladder() -> tuple[MedialGraph, int, int]:
    """Two junctions X and Y joined by four branches, bowed apart: X and Y each pairing them
    0-1 and 2-3 leaves two loops; either one pairing them otherwise makes one line."""
    graph = MedialGraph()
    x = graph.add_node(np.array([0.0, 0.0]), 2.0)
    y = graph.add_node(np.array([100.0, 0.0]), 2.0)
    for bow in (-30.0, -10.0, 10.0, 30.0):
        points = np.array([[0.0, 0.0], [50.0, bow], [100.0, 0.0]])
        graph.add_branch(Branch(x, y, points, np.full(3, 2.0), np.ones(2)))
    return graph, x, y


@pytest.mark.parametrize("weaker", ["x", "y"])
def test_of_two_pairings_at_the_cap_the_one_with_weaker_evidence_is_changed(weaker):
    """Either junction's change reconnects the line at the same capped cost (both verdicts
    as sure as the costs allow); the evidence uncapped says which is less sure: the one
    changed. Before, the later node was changed whatever its evidence: a cursive e's
    crossing read by the CNN and geometry alike (p 0.9999) was turned into a touch instead of
    a d's bowl meeting the stem at a corner, read a crossing at p 0.986
    (make_a_tidy_paddle-36-18), or a touch the geometry alone called a crossing
    (the_kettle_and_the_teacup-7-33)."""
    graph, x, y = _ladder()
    ranked = {x: (APART, ACROSS, OTHER), y: (APART, ACROSS, OTHER)}
    costs = {x: CAPPED, y: CAPPED}
    sure = (0.0, 12.0, 13.7)  # p 0.99999
    evidence = {x: CAPPED if weaker == "x" else sure, y: CAPPED if weaker == "y" else sure}
    pairing, _ = connect_pairings(graph, ranked, costs, evidence=evidence)
    changed = x if weaker == "x" else y
    kept = y if weaker == "x" else x
    assert pairing[changed] != APART
    assert pairing[kept] == APART


@pytest.mark.parametrize("seed, index", [
    (7, 33),  # the_kettle_and_the_teacup, 2.25 px: the e of "teacup"
    (36, 18),  # make_a_tidy_paddle, 3.5 px: the e of "paddle"
])
def test_a_sure_crossing_keeps_its_pairing_where_a_less_sure_one_reconnects_the_line(seed, index):
    """A cursive e's loop crossing, which the CNN and the geometry both read as a crossing,
    was turned into a touch to keep the line one piece, where changing a junction read
    less surely (a touch at a corner taken for a crossing) did the same at the same capped
    cost: the e's loop ran backwards and its crossing was lost. Every ground-truth crossing
    must be matched by an output crossing."""
    from benchmarks.common.render import render_truth, to_uint8
    from benchmarks.metrics.table1 import evaluate
    from benchmarks.sets.cursive import cursive_drawing
    from vectorize import VectorizeOptions, vectorize_image

    gt = cursive_drawing(seed, index)
    gray = render_truth(gt)
    result = vectorize_image(to_uint8(gray), VectorizeOptions(classifier="cnn"))
    assert result.report.strokes == 1
    scores = evaluate(gt, result.drawing, gray)
    assert scores.matched == scores.gt_intersections
