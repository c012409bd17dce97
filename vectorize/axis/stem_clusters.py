"""A stem drawn down and back up through a crossing: a cluster of junctions read as one.

At the base of a cursive h (or k, or any ascender loop whose stem is drawn down and back
up) three passes go through one small stretch of ink: the way in, which goes on up one side
of the loop; the loop's way down, which crosses the way in at a shallow angle and goes on
down the stem; and the stem drawn back up, which turns off into the way on. Their inks
overlap unevenly, so the medial axis there is three to five junctions round a small hole,
or, where the stem drawn back up merges with the others' ink, two or three junctions with
no hole (a tree), or, on thin lines, more junctions round two or more small holes, joined by
short branches, with five feet leaving: the way in, the loop's two sides, the stem (to its
free end) and the way on. Where the line starts at the h, the way in ends free too, and the
stem is the free foot whose pass back up into the way on crosses neither of the two
crossing passes. No pairing at any one of those
junctions describes the three passes (an inner branch carries one to three of them), and
the route then draws the loop backwards, or crosses beside the true crossing, or retraces
an inner branch; at a tree the crossing classifier, shown one junction, calls it a touch.

Read as one: the junctions and the branches between them become one crossing node where
the way in and the way down cross (a degree-4 node whose pairs are known: the loop is drawn
round from the way in, so its way down crosses it), and the stem drawn back up becomes a
branch of its own from the stem's tip along the hole's far side (at a tree, up the stem)
into the way on, beside the crossing rather than through it. The stem is then a spike
drawn down and back up, with a cusp at its tip.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.csgraph import dijkstra

from vectorize.axis.clusters import MAX_BEND, Pairs, linked_groups, merge_cluster, pass_bends
from vectorize.axis.graph import Branch, MedialGraph
from vectorize.axis.simplify import CROSSING_EDGE_BLUR, slot_points, slots

# Stroke widths. The branches round the hole at the cursive h bases measured 0.7-4.4 widths
# (the_acid_ate_the_metal-0-38, 3.5 px lines), 2.1-6.7 (the_planet_men_tend_the_yacht-1-37,
# 2.25 px lines measured 1.5 px wide), up to 7.13 (ethnically-1-26, the hole's far side) and 7.45
# (a line of h's drawn at seed 7): the hole runs as far as the way in and the way down share
# ink, w / sin(a / 2) for passes crossing at a. The bound is that at a = 15 degrees, 7.7 widths
# (`route_inspection.BAND_MAX_WIDTHS`, 6, is 19 degrees).
HOLE_BRANCH_WIDTHS = 1.0 / np.sin(np.radians(15.0 / 2.0))
# Where three passes share a tree's band, their crossing is estimated from the two crossing
# passes' courses either side of it (`place`), on each branch between these stroke widths
# beyond the band: nearer its ends than a crossing's usual window (1-4 widths), each pass is
# fitted where it runs on its own, and extrapolated less far. Estimate to true crossing over
# the 68 such nodes of cursive seeds 0-13 and 30-35: median 1.15 px, 6 over 3 px (1-4 widths:
# 1.85 px, 20 over 3; 0.5-3: 1.14, 7; 0.5-2: 1.41, 8; 0.75-2.5: 1.45, 13).
TREE_WINDOW = (0.5, 2.5)


def merge_stem_clusters(graph: MedialGraph, *, stroke_width: float, ends: int, place, through: dict | None = None,
                        may_merge=None) -> dict[int, int]:
    """Find the clusters of junctions where a stem drawn down and back up meets a crossing
    (module doc) and read each as one crossing and one branch beside it, in place.

    ends: free ends the single line is taken to have; a stem's tip is read as a cusp only
    while the drawing has more free ends than that. through: nodes already merged where
    three passes cross (left alone). may_merge(branch) -> False keeps a cluster apart (a
    user's split edit). place(graph, node, passes, window=None) -> (2,) px: an estimate of
    where the way in and the loop's way down (`passes`, two slot pairs at `node` merged in
    `graph`) cross, from their courses between `window` stroke widths beyond the node's span
    (`vectorize.junctions.crossing_point.passes_crossing`, passed in: the junctions' stage
    comes after this one); the node's place where three passes share the band
    (`TREE_WINDOW`), and which band where a hole's way in does not border its loop's junction. Returns crossing node ->
    its stem's tip, where the fit splits; the tip's other branch is the stem drawn back up
    into the way on. Pair each node's slots with `stem_passes` once simplification is done.
    """
    through = through or {}
    if len(graph.nodes_of_degree(1)) <= ends:
        return {}
    junctions = [n for n in graph.incident if graph.degree(n) >= 3 and n not in through]
    known = set(junctions)
    # The band's width as `simplify` takes a crossing's shared ink: the measured width and
    # the anti-aliased edges the overlapping passes add (a 2.5 px line measures 1.5 px, and
    # an h's band 12.6 px long there is 8.4 measured widths).
    band_width = stroke_width + CROSSING_EDGE_BLUR
    short = [bid for bid, b in graph.branches.items()
             if b.a != b.b and b.a in known and b.b in known and b.length <= HOLE_BRANCH_WIDTHS * band_width]
    if not short:
        return {}
    tips = {}
    for members in linked_groups(graph, junctions, short):
        inside = set(members)
        # Besides the loop (the longest, an ascender far longer than the hole's sides), one
        # branch between the junctions for each junction (one hole), one fewer (a tree: the
        # passes' inks merge with no hole between them) or more (holes: on thin lines the
        # three passes' inks touch and part again along the band, 7 junctions round 2 holes
        # at 2-2.5 px). A side may be longer than the short branches that found the cluster:
        # where the line is thin the measured width falls short of the drawn one (1.5 px
        # measured for lines drawn 2-2.25 px wide).
        joining = sorted({bid for n in members for bid in graph.incident[n]
                          if graph.branches[bid].a in inside and graph.branches[bid].b in inside},
                         key=lambda bid: (graph.branches[bid].length, bid))
        tree = len(joining) == len(members)
        if len(members) < 2 or len(joining) < len(members):
            continue
        inner = sorted(joining[:-1])
        # The loop leaves the ink the passes share and comes back: longer than a short
        # branch and than the hole's sides together (else the cluster has no loop).
        loop = graph.branches[joining[-1]].length
        if loop <= max(HOLE_BRANCH_WIDTHS * stroke_width, sum(graph.branches[b].length for b in inner)):
            continue
        if may_merge is not None and not all(may_merge(graph.branches[b]) for b in inner):
            continue
        feet = [(n, bid) for n in members for bid, _ in slots(graph, n) if bid not in inner]
        stems = [(n, bid) for n, bid in feet if graph.degree(graph.branches[bid].other(n)) == 1]
        loops = [bid for _, bid in feet if graph.branches[bid].a in inside and graph.branches[bid].b in inside]
        # Five feet: the way in and the way on, the loop's two sides (one branch) and the stem;
        # the way in ends free too where the line starts at the h.
        if len(feet) != 5 or len(stems) not in (1, 2) or len(loops) != 2:
            continue
        # A foot to a degree-2 node is another cluster's stem drawn back up (its tip): this
        # cluster then has no way in or no way on of its own, and is left as it is.
        if any(graph.degree(graph.branches[bid].other(n)) == 2 for n, bid in feet):
            continue
        trial, renamed = graph.copy(), {}
        node = merge_cluster(trial, sorted(members), inner, renamed=renamed)
        if len(stems) == 2:
            # Two free feet: the way in and the stem. Both readings pair the same feet in the
            # two crossing passes; they differ in the third, the stem drawn back up into the
            # way on, which runs beside the crossing and crosses neither (the stem's foot and
            # the way on's are neighbours round the node). Neither or both: left as it is.
            beside = [stem for stem in stems
                      if _beside(trial, node, stroke_width, graph.branches[stem[1]].other(stem[0]))]
            if len(beside) != 1:
                continue
            stems = beside
        tip = graph.branches[stems[0][1]].other(stems[0][0])
        passes, bend = stem_passes(trial, node, stroke_width, tip)
        if bend > MAX_BEND:
            continue
        on_here = slots(trial, node)[passes[2][1]][0]
        on = next(old for old, new in renamed.items() if new == on_here)
        # The way in and the way down cross at a shallow angle and share one band of ink. The
        # way in goes from its junction up to the loop's, the way down from the loop's through
        # the way in's to the stem: a branch joining those two junctions carries both. If the
        # stem drawn back up reaches the way on without it, it carries no third pass, and two
        # passes' ink is narrowest where they cross (one width there, wider either way as they
        # part): the node goes to its least medial radius. If the stem drawn back up runs along
        # it too (a tree whose way on leaves at the loop's junction), the band's width tells
        # nothing of where two of the three cross: the node goes to their estimated crossing
        # (from each pass's course on either side). A tree whose way in's junction does not
        # border the loop's (the way on leaves between them) is left as it is. A hole without
        # such a branch: the band is the inner branch nearest the estimate and they cross at
        # its middle (as `simplify` merges a crossing's two halves at the middle of the
        # branch between them).
        into = _junction(graph, next(old for old, new in renamed.items()
                                     if new == slots(trial, node)[passes[0][0]][0]), inside)
        loop_at = {graph.branches[joining[-1]].a, graph.branches[joining[-1]].b}
        # A junction inside another's maximal disc is the same junction at the ink's
        # resolution (a way on leaving a pixel or two from the way in's junction does not
        # leave inside the band).
        near_in = _blob(graph, {into}, inner)
        near_loop = _blob(graph, loop_at, inner)
        # A branch with one end at each; none where the two blobs are one.
        joins = [] if near_in & near_loop else [
            b for b in inner if (graph.branches[b].a in near_in) != (graph.branches[b].b in near_in)
            and (graph.branches[b].a in near_loop) != (graph.branches[b].b in near_loop)]
        if tree and len(joins) != 1:
            continue
        band = joins[0] if len(joins) == 1 else None
        read = band is not None and _shortest(graph, [b for b in inner if b != band], stems[0][0],
                                              _junction(graph, on, inside)) is not None
        if read:
            radii = graph.branches[band].radii
            centre = graph.branches[band].points[1 + int(np.argmin(radii[1:-1])) if len(radii) > 2 else 0]
        elif tree:
            band, centre = None, np.asarray(place(trial, node, passes[:2], TREE_WINDOW), dtype=float)
        else:
            estimate = place(trial, node, passes[:2])
            band = min(inner, key=lambda b: float(np.min(np.hypot(*(graph.branches[b].points - estimate).T))))
            arc = graph.branches[band].arc
            centre = graph.branches[band].points[int(np.searchsorted(arc, arc[-1] / 2.0))]
        up = _stem_back_up(graph, stems[0], on, inside, [b for b in inner if b != band], inner)
        graph.remove_branch(on)
        band_ends = [graph.positions[n] for n in
                     (members if band is None else (graph.branches[band].a, graph.branches[band].b))]
        node = merge_cluster(graph, sorted(members), inner, centre)
        if tree:
            # The ink the crossing passes share is the band; the tree's other junction is
            # where the stem and the way on part from it, outside the crossing (the uncertain
            # zone round the node, which the fit bridges, reaches as far as the span).
            graph.spans[node] = float(max(np.hypot(*(end - centre)) for end in band_ends))
        graph.add_branch(up)
        tips[node] = up.a
    return tips


def stem_passes(graph: MedialGraph, node: int, stroke_width: float, tip: int) -> tuple[Pairs, float]:
    """The passes through a merged stem cluster (slot pairs) and the largest bend (degrees) of
    the two that cross: the way in up one side of the loop, the loop's other side down the
    stem and, while the way on still ends at the node, the stem back up into it.

    The loop is drawn round from the way in, so its way down crosses the way in: of its two
    sides, the way in goes up the one that makes the two passes cross (their feet alternate
    round the node). Which free foot is the way in: the one that runs on straightest into
    its side. The turn from the stem into the way on is a cusp's, and is not measured.
    Directions are taken where each branch leaves the cluster's ink (a width beyond its
    span), not along the branches: a loop's two sides run side by side, and further out
    they meet again at its top. tip: the stem's far end (`merge_stem_clusters` returns it);
    another foot may end at a node of degree 2 too (the tip of the stem before it).
    """
    node_slots = slots(graph, node)
    dirs = _leaving(graph, node, graph.spans.get(node, 0.0) + stroke_width)
    angle = np.arctan2(dirs[:, 1], dirs[:, 0])
    ends = [graph.branches[bid].other(node) for bid, _ in node_slots]
    stem = [i for i, far in enumerate(ends) if far == tip]
    loop = [i for i, far in enumerate(ends) if far == node]
    free = [i for i in range(len(node_slots)) if i not in stem and i not in loop]

    def between(x: int, a: int, b: int) -> bool:
        return (angle[x] - angle[a]) % (2 * np.pi) < (angle[b] - angle[a]) % (2 * np.pi)

    best, best_cost = (), np.inf
    for into in free:
        side, other = loop if between(loop[1], into, loop[0]) != between(stem[0], into, loop[0]) else loop[::-1]
        on = [i for i in free if i != into]
        pairs = ((into, side), (other, stem[0])) + (((stem[-1], on[0]),) if on else ())
        cost = 1.0 + float(np.dot(dirs[into], dirs[side]))
        if cost < best_cost:
            best, best_cost = pairs, cost
    return best, max(pass_bends(dirs, best[:2]))


def _beside(graph: MedialGraph, node: int, stroke_width: float, tip: int) -> bool:
    """Whether, read with its stem to `tip`, the merged cluster's third pass (the stem drawn
    back up into the way on) crosses neither of the two that cross each other: no foot of
    theirs lies between the stem's foot and the way on's on one side round the node only."""
    passes, _ = stem_passes(graph, node, stroke_width, tip)
    if len(passes) < 3:
        return False
    dirs = _leaving(graph, node, graph.spans.get(node, 0.0) + stroke_width)
    angle = np.arctan2(dirs[:, 1], dirs[:, 0])
    stem, on = passes[2]
    turn = (angle[on] - angle[stem]) % (2 * np.pi)
    inside = [(angle[i] - angle[stem]) % (2 * np.pi) < turn for pair in passes[:2] for i in pair if i != stem]
    return all(inside) or not any(inside)


def _blob(graph: MedialGraph, nodes: set[int], inner: list[int]) -> set[int]:
    """`nodes` and the junctions an `inner` branch joins to one of them inside one of the two's
    maximal disc (the branch shorter than the larger medial radius)."""
    result = set(nodes)
    for bid in inner:
        branch = graph.branches[bid]
        if branch.length < max(graph.radii[branch.a], graph.radii[branch.b]) and (branch.a in nodes or branch.b in nodes):
            result |= {branch.a, branch.b}
    return result


def _junction(graph: MedialGraph, bid: int, inside: set[int]) -> int:
    """The end of branch `bid` that is one of the cluster's junctions (`inside`)."""
    branch = graph.branches[bid]
    return branch.a if branch.a in inside else branch.b


def _leaving(graph: MedialGraph, node: int, radius: float) -> np.ndarray:
    """(D, 2) unit vectors from `node` to where each of its branches (in `slots` order)
    first reaches `radius` px from it (its far end if it never does)."""
    centre = graph.positions[node]
    result = []
    for slot in slots(graph, node):
        points = slot_points(graph, slot)
        out = np.flatnonzero(np.hypot(*(points - centre).T) >= radius)
        chord = points[out[0] if len(out) else -1] - centre
        result.append(chord / max(float(np.hypot(*chord)), 1e-9))
    return np.array(result)


def _stem_back_up(graph: MedialGraph, stem: tuple[int, int], on: int, inside: set[int], beside: list[int],
                  inner: list[int]) -> Branch:
    """The stem drawn back up into the way on, as one branch from the stem's tip to the way
    on's far end: up the stem, along the hole's other side (the shortest way between the two
    feet over `beside`, the inner branches but the band where the other two passes cross;
    over all `inner` ones if that is no way) and on. stem: (junction, branch id); on: the
    way on's branch id."""
    at, bid = stem
    end = next(n for n in (graph.branches[on].a, graph.branches[on].b) if n in inside)
    path = _shortest(graph, beside, at, end)
    if path is None:
        path = _shortest(graph, inner, at, end) or []
    parts, node = [graph.branches[bid].oriented_from(graph.branches[bid].other(at))], at
    for b in path:
        parts.append(graph.branches[b].oriented_from(node))
        node = graph.branches[b].other(node)
    parts.append(graph.branches[on].oriented_from(end))
    points = np.vstack([parts[0].points] + [p.points[1:] for p in parts[1:]])
    radii = np.concatenate([parts[0].radii] + [p.radii[1:] for p in parts[1:]])
    sins = np.concatenate([p.sins for p in parts])
    return Branch(parts[0].a, parts[-1].b, points, radii, sins)


def _shortest(graph: MedialGraph, branches: list[int], start: int, end: int) -> list[int] | None:
    """Branch ids of the shortest way from `start` to `end` over `branches`, or None."""
    if start == end:
        return []
    nodes = sorted({n for b in branches for n in (graph.branches[b].a, graph.branches[b].b)} | {start, end})
    at = {n: i for i, n in enumerate(nodes)}
    weights = np.full((len(nodes), len(nodes)), np.inf)
    which = {}
    for b in branches:
        i, j = at[graph.branches[b].a], at[graph.branches[b].b]
        if graph.branches[b].length < weights[i, j]:
            weights[i, j] = weights[j, i] = graph.branches[b].length
            which[i, j] = which[j, i] = b
    dist, pred = dijkstra(np.where(np.isfinite(weights), weights, 0.0), directed=False,
                          indices=at[start], return_predecessors=True)
    if not np.isfinite(dist[at[end]]):
        return None
    path, k = [], at[end]
    while k != at[start]:
        path.append(which[pred[k], k])
        k = pred[k]
    return path[::-1]
