"""Single-line mode on drawings that need retracing: one piece of ink is one stroke, the
retraced branches are the shortest possible, and the curve stays in the ink with a cusp
where the pen turns back."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.spatial import cKDTree

from tests.conftest import render_polylines
from vectorize import VectorizeOptions, vectorize_image
from vectorize.route.route_matching import PRUNE_FROM, match_odd

OPTIONS = VectorizeOptions(classifier="geometric")
WIDTH = 6.0


def _dense(polyline, step=0.25) -> np.ndarray:
    pts = []
    for a, b in zip(polyline[:-1], polyline[1:]):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(2, int(np.linalg.norm(b - a) / step))
        pts.append(a + (b - a) * np.linspace(0, 1, n)[:, None])
    return np.vstack(pts)


def _excursion(drawing, polylines) -> float:
    """Largest distance (px) of the output from the drawn centre lines."""
    tree = cKDTree(np.vstack([_dense(p) for p in polylines]))
    return max(float(tree.query(s.sample_evenly(0.5))[0].max()) for s in drawing.strokes)


def test_retraced_stem_stays_in_the_ink_and_turns_back_in_a_cusp():
    # A baseline with a stem drawn up and back down the same line, shorter than either arm
    # of the baseline (so retracing it is the cheapest way to draw this in one stroke).
    path = [(60, 300), (200, 300), (200, 190), (200, 300), (340, 300)]
    result = vectorize_image(render_polylines([path], width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    stroke = result.drawing.strokes[0]
    assert _excursion(result.drawing, [path]) <= WIDTH / 2 + 1
    # Near the stem's tip the direction of travel reverses: a cusp, not a loop.
    s = np.linspace(0, stroke.length, 4000)
    pts = stroke.points_at_lengths(s)
    tip = int(np.argmin(np.linalg.norm(pts - [200, 190], axis=1)))
    assert np.linalg.norm(pts[tip] - [200, 190]) < WIDTH
    before = stroke.tangents_at(stroke.parameters_at_lengths(s[tip] - 3 * WIDTH))
    after = stroke.tangents_at(stroke.parameters_at_lengths(s[tip] + 3 * WIDTH))
    assert float(np.dot(before, after)) < -0.95
    # The stem is drawn twice, nothing else.
    assert stroke.length == pytest.approx(280 + 2 * 110, abs=4 * WIDTH)


def test_crossbar_out_and_back_across_a_stem_is_one_stroke():
    # A "t": a stem and a crossbar through it. Four free ends: two arms must be retraced.
    lines = [[(200, 60), (200, 340)], [(130, 140), (270, 140)]]
    result = vectorize_image(render_polylines(lines, width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    assert _excursion(result.drawing, lines) <= WIDTH / 2 + 1
    # The cheapest retrace: the two crossbar arms (70 px each) - the crossbar drawn out and
    # back - not the stem's upper part (80) with an arm.
    assert result.drawing.strokes[0].length == pytest.approx(280 + 140 + 140, abs=4 * WIDTH)


def test_four_odd_nodes_retrace_the_shortest_branch():
    # A line with a branch off it: three free ends and one junction, arms of 150, 200, 60 px.
    lines = [[(50, 200), (200, 200), (400 - 50, 200)], [(200, 200), (200, 140)]]
    result = vectorize_image(render_polylines(lines, width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    assert result.drawing.strokes[0].length == pytest.approx(300 + 2 * 60, abs=4 * WIDTH)
    # And with the short arm elsewhere, the retrace moves with it.
    lines = [[(50, 200), (110, 200)], [(110, 200), (110, 40)], [(110, 200), (110, 360)]]
    result = vectorize_image(render_polylines(lines, width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    assert result.drawing.strokes[0].length == pytest.approx(320 + 2 * 60, abs=4 * WIDTH)


def _brute_force(dist, end_cost):
    m = len(dist)
    best = np.inf
    for ends in itertools.combinations(range(m), 2):
        rest = [i for i in range(m) if i not in ends]

        def pairings(items):
            if not items:
                yield []
                return
            first = items[0]
            for k in range(1, len(items)):
                for tail in pairings(items[1:k] + items[k + 1:]):
                    yield [(first, items[k])] + tail

        for pairs in pairings(rest):
            best = min(best, sum(dist[i, j] for i, j in pairs) + end_cost[list(ends)].sum())
    return best


@pytest.mark.parametrize("seed", range(4))
def test_exact_matching_is_optimal(seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(0, 100, (8, 2))
    dist = np.linalg.norm(points[:, None] - points[None], axis=2)
    end_cost = rng.uniform(0, 30, 8)
    pairs, ends = match_odd(dist, end_cost)
    assert len(ends) == 2 and sorted(set(sum(pairs, ()) + tuple(ends))) == list(range(8))
    cost = sum(dist[i, j] for i, j in pairs) + end_cost[ends].sum()
    assert cost == pytest.approx(_brute_force(dist, end_cost))


def test_large_matchings_are_complete():
    rng = np.random.default_rng(7)
    m = PRUNE_FROM + 6
    points = rng.uniform(0, 100, (m, 2))
    dist = np.linalg.norm(points[:, None] - points[None], axis=2)
    pairs, ends = match_odd(dist, np.zeros(m))
    assert sorted(sum(pairs, ()) + tuple(ends)) == list(range(m)) and len(ends) == 2


def test_three_passes_through_one_point_go_straight_through():
    # A closed line that crosses itself three times at one point (three lines through the
    # centre, 60 degrees apart, joined by arcs at their ends): the paper's Fig. 12 case.
    centre = np.array([200.0, 200.0])
    path = []
    for k in range(3):
        a = np.radians(60.0 * k)
        d = np.array([np.cos(a), np.sin(a)])
        start, end = centre - 150 * d, centre + 150 * d
        path.extend([start, end])
    # Arcs between the line ends: end of line k to start of line k + 1 around the outside.
    poly = []
    for k in range(3):
        a0, a1 = path[2 * k + 1], path[(2 * k + 2) % 6]
        poly.extend(_dense([path[2 * k], a0], step=2.0))
        ang0, ang1 = (np.arctan2(*(p - centre)[::-1]) for p in (a0, a1))
        ang1 = ang0 + ((ang1 - ang0) % (2 * np.pi))
        t = np.linspace(ang0, ang1, 60)
        poly.extend(centre + 150 * np.c_[np.cos(t), np.sin(t)])
    poly = np.array(poly)
    result = vectorize_image(render_polylines([poly], width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    assert result.report.high_degree_junctions == 0
    stroke = result.drawing.strokes[0]
    assert _excursion(result.drawing, [poly]) <= WIDTH / 2 + 1
    # Each pass through the centre is straight: the curve's direction at its three visits
    # of the centre are three directions 60 degrees apart, none turning there.
    s = np.linspace(0, stroke.length, 6000)
    pts = stroke.points_at_lengths(s)
    near = np.linalg.norm(pts - centre, axis=1) < 3.0
    visits = np.split(np.flatnonzero(near), np.flatnonzero(np.diff(np.flatnonzero(near)) > 1) + 1)
    assert len(visits) == 3
    for v in visits:
        before = stroke.tangents_at(stroke.parameters_at_lengths(s[v[0]] - 4 * WIDTH))
        after = stroke.tangents_at(stroke.parameters_at_lengths(s[v[-1]] + 4 * WIDTH))
        assert float(np.dot(before, after)) > np.cos(np.radians(15))


def test_a_long_spike_on_a_closed_loop_is_drawn_once_from_its_tip():
    # A loop (942 px) with a spike of 60 px out of it: ending the line at the spike's base
    # (a junction, a poor end) costs less than drawing 6 % of the drawing twice, so the line
    # starts at the tip and goes round to the base: the shortest line over the ink.
    centre, radius = np.array([180.0, 200.0]), 150.0
    t = np.linspace(0, 2 * np.pi, 240)
    loop = centre + radius * np.c_[np.cos(t), np.sin(t)]
    tip = loop[0] + [60.0, 0.0]
    result = vectorize_image(render_polylines([loop, [loop[0], tip]], width=WIDTH), OPTIONS)
    assert result.report.strokes == 1
    stroke = result.drawing.strokes[0]
    assert stroke.length == pytest.approx(2 * np.pi * radius + 60, abs=6 * WIDTH)
    assert min(np.linalg.norm(stroke.start - tip), np.linalg.norm(stroke.end - tip)) < 2 * WIDTH
