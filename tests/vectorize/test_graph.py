"""The medial-axis graph's bulk operations against the one-branch-at-a-time ones they replace
(same numbers to the last bit, same ids, same incidence order): pruning's measures of many
short branches at once, and joining whole runs of degree-2 nodes at once."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vectorize.axis.graph import Branch, MedialGraph, measure_short
from vectorize.front_stages import axis_stages
from vectorize.options import VectorizeOptions
from vectorize.raster.image_io import load_image
from vectorize.stage_clock import StageClock
from vectorize.stroke import edge_lengths, lengths

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _axis(name: str) -> tuple[MedialGraph, float]:
    """The unpruned medial-axis graph of an example drawing, and its stroke width."""
    ink, _, graph = axis_stages(load_image(EXAMPLES / name)[0], VectorizeOptions(), StageClock())
    return graph, ink.stroke_width


def _fresh(branch: Branch) -> Branch:
    return Branch(branch.a, branch.b, branch.points, branch.radii, branch.sins)


def _dissolve_one_by_one(graph: MedialGraph) -> None:
    """The join as it was first written: each degree-2 node's two branches made into one
    new branch at once (the oracle for `MedialGraph.dissolve_degree_two`)."""
    for node in [n for n, inc in graph.incident.items() if len(inc) == 2]:
        first, second = graph.incident[node]
        if first == second:
            continue
        b1 = graph.remove_branch(first).oriented_from(node)
        b2 = graph.remove_branch(second).oriented_from(node)
        joined = Branch(b1.b, b2.b, np.vstack([b1.points[::-1], b2.points[1:]]),
                        np.concatenate([b1.radii[::-1], b2.radii[1:]]), np.concatenate([b1.sins[::-1], b2.sins]))
        del graph.incident[node], graph.positions[node], graph.radii[node]
        graph.add_branch(joined)


def _leaves_removed(graph: MedialGraph) -> MedialGraph:
    """The graph without its leaf branches, as pruning leaves it before joining: long
    strokes cut into runs of branches at many degree-2 nodes."""
    for node in [n for n, inc in graph.incident.items() if len(inc) == 1]:
        junction = graph.branches[graph.incident[node][0]].other(node)
        if graph.degree(junction) >= 3:
            graph.remove_node(node)
    return graph


def test_edge_lengths_are_numpys_norm_to_the_bit():
    rng = np.random.default_rng(3)
    for size in (1, 2, 3, 50, 4000):
        points = rng.normal(size=(size, 2)) * 10.0 ** rng.uniform(-3, 4)
        expected = np.linalg.norm(np.diff(points, axis=0), axis=1)
        assert np.array_equal(edge_lengths(points), expected)
        assert np.array_equal(edge_lengths(points[::-1])[::-1], expected)


def test_lengths_and_two_term_sums_are_numpys_to_the_bit():
    """`lengths` and the sums of two products written out (circumcentres, object angles,
    edge midpoints) give numpy's reductions' numbers, infinities and NaNs included (flat
    triangles' circumcentres are infinite)."""
    rng = np.random.default_rng(5)
    for size in (0, 1, 7, 8, 9, 1000, 50_000):
        v = rng.normal(size=(size, 2)) * 10.0 ** rng.uniform(-8, 6, size=(size, 1))
        w = rng.normal(size=(size, 2)) * 1e3
        if size > 8:
            v[3], v[5, 1], w[7] = np.inf, -np.inf, np.nan
        with np.errstate(invalid="ignore", over="ignore"):
            assert np.array_equal(lengths(v), np.linalg.norm(v, axis=1), equal_nan=True)
            assert np.array_equal(v[:, 0] * w[:, 0] + v[:, 1] * w[:, 1], (v * w).sum(1), equal_nan=True)
            pairs = rng.integers(0, max(size, 1), size=(size, 2))
            ends = w if size else np.zeros((1, 2))
            assert np.array_equal((ends[pairs[:, 0]] + ends[pairs[:, 1]]) / 2.0, ends[pairs].mean(axis=1),
                                  equal_nan=True)


def test_short_branches_measured_together_as_each_alone():
    graph, _ = _axis("hershey-HersheySans1-ampersand.png")
    rng = np.random.default_rng(5)
    branches = [_fresh(b) for b in graph.branches.values()]
    axis = len(branches)
    # Plus random branches of every short size, radii and sins included (an empty one too).
    for count in [1, *range(1, 12)] * 40:
        branches.append(Branch(0, 1, rng.normal(size=(count, 2)) * rng.uniform(0.01, 80.0), np.ones(count),
                               rng.random(count - 1)))
    measure_short(branches)
    measured = [b for b in branches if "length" in b.__dict__]
    # The axis's branches are mostly noise spurs of one or two edges.
    assert sum("length" in b.__dict__ for b in branches[:axis]) > 0.6 * axis
    assert [len(b.points) <= 8 for b in branches] == ["length" in b.__dict__ for b in branches]
    for branch in measured:
        alone = _fresh(branch)
        assert branch.length == alone.length == float(np.linalg.norm(np.diff(branch.points, axis=0), axis=1).sum())
        assert branch.significance == alone.significance


@pytest.mark.parametrize("name", ["hershey-HersheySans1-ampersand.png", "loops.png", "spike-drawing.png"])
def test_joining_runs_at_once_is_joining_node_by_node(name):
    graph, _ = _axis(name)
    ours, oracle = _leaves_removed(graph.copy()), _leaves_removed(graph.copy())
    degree_two = sum(len(inc) == 2 for inc in ours.incident.values())
    assert degree_two > 20  # many joins, runs of them along the strokes
    ours.dissolve_degree_two()
    _dissolve_one_by_one(oracle)
    assert list(ours.branches) == list(oracle.branches)  # ids and their order
    assert ours.incident == oracle.incident and list(ours.positions) == list(oracle.positions)
    assert not any(len(inc) == 2 and inc[0] != inc[1] for inc in ours.incident.values())
    for bid, branch in ours.branches.items():
        expected = oracle.branches[bid]
        assert (branch.a, branch.b) == (expected.a, expected.b)
        for field in ("points", "radii", "sins"):
            assert np.array_equal(getattr(branch, field), getattr(expected, field))
        assert np.array_equal(branch.edge_lengths, np.linalg.norm(np.diff(expected.points, axis=0), axis=1))
        assert branch.length == expected.length and branch.significance == expected.significance


def test_pruned_axis_keeps_the_drawing_and_its_lengths_exact():
    """Pruning (bulk measures, joins at once) on a real drawing: branches still run node to
    node, every length is what the branch measures afresh, and copies keep the measures."""
    from vectorize.axis.pruning import prune

    graph, width = _axis("hershey-HersheySans1-ampersand.png")
    before = len(graph.branches)
    removed = prune(graph, threshold=0.95, stroke_width=width)
    assert removed > 50 and len(graph.branches) < before / 5
    copy = graph.copy()
    for bid, branch in graph.branches.items():
        assert np.array_equal(branch.points[0], graph.positions[branch.a])
        assert np.array_equal(branch.points[-1], graph.positions[branch.b])
        assert len(branch.sins) == len(branch.points) - 1 == len(branch.radii) - 1
        assert branch.length == _fresh(branch).length
        assert copy.branches[bid].length == branch.length and copy.branches[bid] is not branch


def test_slot_directions_from_kept_arc_lengths_are_the_direct_ones():
    """Directions at every junction of a pruned drawing, from the branches' kept arc lengths,
    equal the chord computed afresh from the points (numpy's norm, diff, cumsum, interp)."""
    from vectorize.axis.pruning import prune
    from vectorize.axis.simplify import slot_direction, slot_points, slots

    graph, width = _axis("hershey-HersheySans1-ampersand.png")
    prune(graph, threshold=0.95, stroke_width=width)
    checked = 0
    for node in [n for n in graph.incident if graph.degree(n) >= 3]:
        for slot in slots(graph, node):
            points = slot_points(graph, slot)
            arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
            for reach in (0.5 * width, 2.5 * width, 9.0 * width, 1e6):
                target = min(reach, arc[-1])
                chord = np.array([np.interp(target, arc, points[:, 0]), np.interp(target, arc, points[:, 1])]) - points[0]
                expected = chord / np.linalg.norm(chord)
                assert np.array_equal(slot_direction(graph, slot, reach), expected)
                checked += 1
    assert checked >= 40
