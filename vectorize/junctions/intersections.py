"""Deciding how the pen went through a degree-4 node: crossing straight over, or touching.

A degree-4 node joins four branches. The pen either crossed (each branch continues into the
one opposite it) or the two curves touched and turned back (two branches pair up on each
side). A classifier gives the probability of a crossing; when it says "touching", the
pairing with the smaller tangent discontinuity is taken (paper, Section 3.3.1). Any
classifier that follows `IntersectionClassifier` plugs in without touching the traversal
(`vectorize.junctions.classifiers.make_classifier` builds the named ones).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from vectorize.axis.clusters import pass_bends

if TYPE_CHECKING:
    from vectorize.axis.graph import MedialGraph


# A configuration pairs the four branch slots 0..3 into two passes through the node.
Pairing = tuple[tuple[int, int], tuple[int, int]]
ALL_PAIRINGS: tuple[Pairing, ...] = (((0, 1), (2, 3)), ((0, 2), (1, 3)), ((0, 3), (1, 2)))


@dataclass(frozen=True, eq=False)
class Junction:
    """One degree-4 node of the simplified medial-axis graph.

    center: (2,) x, y in px of the working image; directions: (4, 2) unit tangents of the
    four branches pointing away from the node; width: local stroke width in px;
    crossing: (2,) px where the two straight-through passes are estimated to cross
    (`vectorize.junctions.crossing_point`), where image classifiers centre their crops; None: center.
    ink: (K, 3) x, y, radius px of discs covering the junction's own ink
    (`vectorize.junctions.junction_ink.own_ink`): an image classifier sees only that ink on
    paper; None: the whole image.
    """

    center: np.ndarray
    directions: np.ndarray
    width: float
    crossing: np.ndarray | None = None
    ink: np.ndarray | None = None

    @property
    def crop_center(self) -> np.ndarray:
        """Where an image classifier looks: the estimated crossing, else the node."""
        return self.center if self.crossing is None else self.crossing


@dataclass(frozen=True)
class JunctionVerdict:
    """A classifier's answer for one junction.

    p_crossing: probability that the pen crossed straight over, in [0, 1];
    confidence: how sure the classifier is of its majority answer, in [0.5, 1].
    """

    p_crossing: float
    confidence: float

    @property
    def is_crossing(self) -> bool:
        return self.p_crossing >= 0.5


class IntersectionClassifier(Protocol):
    """Anything that can tell crossings from touchings for a batch of junctions."""

    name: str

    def classify(self, gray: np.ndarray, junctions: Sequence[Junction],
                 stroke_width: float) -> list[JunctionVerdict]:
        """gray: (H, W) float32 in [0, 1], 1 = paper; one verdict per junction."""
        ...


def turn_cost(directions: np.ndarray, pairing: Pairing) -> float:
    """Total bending of a pairing: for each pass a->b, 1 + cos(angle between the branches).

    A pass straight through (branches pointing in opposite directions) costs 0, a U-turn 2.
    """
    d = np.asarray(directions, dtype=float)
    return float(sum(1.0 + float(np.dot(d[a], d[b])) for a, b in pairing))


def crossing_pairing(directions: np.ndarray) -> Pairing:
    """The pairing of branches that lie opposite each other in angular order around the node.

    Two strokes that cross alternate around the node (A, B, A', B'); two that touch come in
    side by side (A, A', B', B). Angular order, not tangent smoothness, tells them apart:
    at a tangential touch both the crossing and the right touching pairing are smooth.
    """
    d = np.asarray(directions, dtype=float)
    order = np.argsort(np.arctan2(d[:, 1], d[:, 0]), kind="stable")
    a, b, c, e = (int(i) for i in order)
    return _normal((a, c), (b, e))


def touching_pairings(directions: np.ndarray) -> tuple[Pairing, Pairing]:
    """The two pairings of angular neighbours, the smoother (smaller turn) first."""
    d = np.asarray(directions, dtype=float)
    order = np.argsort(np.arctan2(d[:, 1], d[:, 0]), kind="stable")
    a, b, c, e = (int(i) for i in order)
    options = [_normal((a, b), (c, e)), _normal((b, c), (e, a))]
    return tuple(sorted(options, key=lambda p: turn_cost(d, p)))  # type: ignore[return-value]


def sharp_touch(directions: np.ndarray) -> bool:
    """Whether touching would turn a pass sharply where going straight through does not.

    Two curves that touch are tangent at the contact: each runs on smoothly on its own side,
    so the touching pairing bends little (at most 28 degrees over the branches' reach at
    the 40 touches of the benchmark's touch set, seed 0, while going straight bent at most 6). A touching pairing that must turn a pass by more than
    `TOUCH_MAX_BEND` while the straight-through pairing bends less than
    `STRAIGHT_MAX_BEND` is not a touch: a stroke bending into a crossing (a cursive e's
    way in, bending into its loop where the loop's side comes down across it).
    """
    straight = max(pass_bends(directions, crossing_pairing(directions)))
    touch = max(pass_bends(directions, touching_pairings(directions)[0]))
    return touch > TOUCH_MAX_BEND and straight < STRAIGHT_MAX_BEND


def lone_junctions(centers: np.ndarray, spans: np.ndarray, reach: float, apart: np.ndarray | None = None) -> np.ndarray:
    """(N,) bool: no other junction within `reach` px plus both junctions' spans (px of
    shared ink, (N,)) of each centre ((N, 2) px). Branch directions measured `reach` beyond
    a junction's span run through a nearer one's ink (two crossings in one band of three
    passes): there they do not show how the strokes bend. apart: (N, N) px between the
    junctions along the line (`along_line`), where the directions are measured; default:
    straight between the centres (never more than along the line)."""
    c = np.asarray(centers, dtype=float).reshape(-1, 2)
    s = np.asarray(spans, dtype=float).reshape(-1)
    if apart is None:
        apart = np.hypot(*(c[:, None, :] - c[None, :, :]).transpose(2, 0, 1))
    gap = np.array(apart, dtype=float) - s[:, None] - s[None, :]
    np.fill_diagonal(gap, np.inf)
    return gap.min(axis=1, initial=np.inf) >= reach


def along_line(graph: MedialGraph, nodes: Sequence[int], limit: float) -> np.ndarray:
    """(N, N) px between `nodes` of `graph` along its branches (inf beyond `limit` px): a
    junction two letters away round a loop may lie near in the image, but the branch
    directions read from the other reach it only after the loop's length."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    index = {n: i for i, n in enumerate(graph.incident)}
    # The shortest of parallel branches (two sides of a hole): a sparse matrix would add
    # their lengths up. A loop from a node back to itself shortens no way.
    shortest: dict[tuple[int, int], float] = {}
    for b in graph.branches.values():
        if b.a != b.b:
            key = tuple(sorted((index[b.a], index[b.b])))
            shortest[key] = min(shortest.get(key, np.inf), max(b.length, 1e-6))
    matrix = coo_matrix((list(shortest.values()), ([i for i, _ in shortest], [j for _, j in shortest])),
                        shape=(len(index), len(index))).tocsr()
    at = [index[n] for n in nodes]
    return dijkstra(matrix, directed=False, indices=at, limit=limit)[:, at]


# Degrees. Touches: the touching pairing bends <= 28; cursive e entries bend 21-30 going
# straight through and 66-80 touching (six at seed 0), and on lines 2 px wide (measured
# 1.5 px, the directions read 2.5 widths out) up to 35-43 going straight
# (hand_me_the_lamp_the_tent_and_the_kettle-1-31, uncle_hank_decided_at_lunchtime-1-34).
TOUCH_MAX_BEND = 45.0
STRAIGHT_MAX_BEND = 45.0


def _normal(first: tuple[int, int], second: tuple[int, int]) -> Pairing:
    pair = sorted([tuple(sorted(first)), tuple(sorted(second))])
    return (pair[0], pair[1])  # type: ignore[return-value]


def ranked_pairings(junction: Junction, verdict: JunctionVerdict) -> tuple[Pairing, Pairing, Pairing]:
    """All three pairings, the classifier's choice first, then the alternatives by plausibility."""
    straight = crossing_pairing(junction.directions)
    touch_a, touch_b = touching_pairings(junction.directions)
    if verdict.is_crossing:
        return straight, touch_a, touch_b
    return touch_a, straight, touch_b


class GeometricClassifier:
    """Tangent continuity only: a crossing when the straight-through pairing is smooth.

    Two strokes that cross leave the node along two nearly straight lines, so the best
    straight-through pairing bends little. Two curves touching tangentially also look
    straight through — which is exactly why this rule gets touchings wrong, and why the
    CNN exists. Kept as a baseline and as a fallback without the model.
    """

    name = "geometric"

    def classify(self, gray: np.ndarray, junctions: Sequence[Junction],
                 stroke_width: float) -> list[JunctionVerdict]:
        verdicts = []
        for junction in junctions:
            straight = turn_cost(junction.directions, crossing_pairing(junction.directions))
            touch = turn_cost(junction.directions, touching_pairings(junction.directions)[0])
            # A crossing is likely when going straight through bends less than turning;
            # at a tangential touch both are smooth and the rule can only guess (p ~ 0.5).
            p = float(1.0 / (1.0 + np.exp(4.0 * (straight - touch))))
            verdicts.append(JunctionVerdict(p_crossing=p, confidence=max(p, 1.0 - p)))
        return verdicts
