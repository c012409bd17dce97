"""Medial-axis simplification (paper 3.2): merge degree-3 pairs into crossings, keep Y-junctions.

Where two strokes meet, the medial axis shows two degree-3 junctions joined by a short
branch instead of one degree-4 node. The branch between the two halves of one crossing
runs through ink laid down twice, so its narrowest radius is the largest of the three
(paper, Fig. 4); at shallow crossings, where all widths are alike, the two halves also
face each other: each one's "foot" (the branch opposite its smallest angle) leads to
the other. A degree-3 node whose foot ends in a free end is a Y-junction: a sharp
feature drawn out and back, kept and traversed twice.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vectorize.axis.graph import Branch, MedialGraph

Slot = tuple[int, str]  # (branch id, which end of it touches the node: "a" or "b")

# Ink deeper than this many line radii is laid down by two passes (`_one_pass_wide`). Between
# the halves of crossings of thin cursive lines (2-2.5 px), two line widths or more beyond
# their discs, the deepest point measured 1.38-2.5 line radii; on a line running alone
# between two forks, 0.98-1.09 (pixel grid, anti-aliasing).
TWO_PASSES_RADIUS = 1.2
# Line radii beyond the junctions' discs from which a branch is long enough for the share of
# its length that runs that deep to tell (`_one_pass_wide`), and the least such share between
# a crossing's halves: measured 0.24 and up between the halves of crossings 16-37 line radii
# apart (cursive, 2-3.5 px lines); a touch beside one line deepened 0.005-0.024 of branches
# 25-58 line radii long between two forks of that line.
LONG_BRANCH_RADII = 16.0
TWO_PASSES_SHARE = 0.1


def slots(graph: MedialGraph, node: int) -> list[Slot]:
    """The branch ends at `node`, in a fixed order (a loop contributes both of its ends)."""
    result: list[Slot] = []
    for bid in graph.incident[node]:
        branch = graph.branches[bid]
        if branch.a == branch.b:
            result.append((bid, "b" if (bid, "a") in result else "a"))
        else:
            result.append((bid, "a" if branch.a == node else "b"))
    return result


def slot_points(graph: MedialGraph, slot: Slot) -> np.ndarray:
    """Points of the slot's branch, starting at the node: (M, 2)."""
    bid, end = slot
    points = graph.branches[bid].points
    return points if end == "a" else points[::-1]


def slot_direction(graph: MedialGraph, slot: Slot, reach: float) -> np.ndarray:
    """Unit tangent leaving the node along the slot: chord to the point `reach` px along it."""
    bid, end = slot
    branch = graph.branches[bid]
    # The branch's own arc lengths (kept: every stage asks for the directions at its nodes).
    points, arc = (branch.points, branch.arc) if end == "a" else (branch.points[::-1], branch.arc_back)
    target = min(reach, arc[-1])
    at = np.array([np.interp(target, arc, points[:, 0]), np.interp(target, arc, points[:, 1])])
    chord = at - points[0]
    norm = np.sqrt(chord.dot(chord))  # what np.linalg.norm computes for one vector
    return chord / norm if norm > 1e-9 else np.array([1.0, 0.0])


def directions(graph: MedialGraph, node: int, reach: float) -> np.ndarray:
    """(D, 2) unit tangents of all slots at `node`, in `slots` order.

    Measured `reach` px beyond the ink the node's strokes share (a merged crossing's or
    touch's joining branch), and further while two branches still leave together: at a
    shallow crossing or a long tangential contact they separate only slowly.
    """
    node_slots = slots(graph, node)
    reach += graph.spans.get(node, 0.0)
    for factor in (1.0, 1.6, 2.4, 3.6):
        dirs = np.array([slot_direction(graph, s, reach * factor) for s in node_slots])
        cos = dirs @ dirs.T
        np.fill_diagonal(cos, -1.0)
        if len(dirs) < 2 or cos.max() < np.cos(np.radians(8.0)):
            break
    return dirs


def foot_slot(dirs: np.ndarray) -> int:
    """Index of the foot of a degree-3 node: the slot opposite the smallest angle."""
    best, foot = -2.0, 0
    for i, j, k in ((0, 1, 2), (0, 2, 1), (1, 2, 0)):
        cos = float(np.dot(dirs[i], dirs[j]))
        if cos > best:
            best, foot = cos, k
    return foot


@dataclass(frozen=True)
class Simplified:
    """Result of simplification: the node kinds the traversal needs.

    y_feet: Y-junction node -> slot index of its foot; y_tips: the free ends of those feet;
    retraced: the Y-junctions whose spike runs back over itself (T-shaped, not V-shaped);
    crossings: degree-4 nodes; merged: pairs merged; unresolved: nodes where three or more
    strokes seem to meet (degree >= 5, or degree 3 that is neither Y, end nor crossing half).
    """

    y_feet: dict
    y_tips: frozenset
    crossings: tuple
    merged: int
    unresolved: tuple
    t_ends: tuple
    retraced: frozenset = frozenset()
    through: dict = field(default_factory=dict)  # node where three passes cross -> slot pairs
    # such a node -> (15,) posterior of the pass scorer over `pass_scorer.PAIRINGS` (slots)
    through_posterior: dict = field(default_factory=dict)
    # crossing nodes the fit holds: where a stem cluster's passes cross (`stem_clusters`)
    held: frozenset = frozenset()


def line_radius(graph: MedialGraph) -> float:
    """The medial radius (px) of the drawing's lines where one pass runs alone: the median
    over every branch point (most of a line drawing's ink is one pass wide). Read from the
    axis itself, not from the estimated stroke width, which falls short on thin lines (a
    2 px line's is read 1.5 px: the distance transform's steps)."""
    radii = [branch.radii for branch in graph.branches.values()]
    return float(np.median(np.concatenate(radii))) if radii else 0.0


def _one_pass_wide(branch: Branch, radius_a: float, radius_b: float, line: float) -> bool:
    """Whether the ink along `branch`, beyond the discs of the junctions at its ends (radii
    `radius_a`, `radius_b` px), is one line wide all along: its medial radius nowhere above
    `TWO_PASSES_RADIUS` times `line` (px). Two passes that cross share ink at least 1.41 line
    radii deep where they cross (a right-angle crossing's inner corners are sqrt 2 radii
    from its centre; deeper at shallower angles): a branch that never gets that deep joins two
    junctions of one line, however their arms point. Told only where the discs leave two line
    widths between them: close to a crossing's centre the pixel grid rounds its inner
    corners off (1.0-1.2 line radii measured between the halves of right-angle crossings of
    2 px lines, 4 px apart). A branch over `LONG_BRANCH_RADII` line radii long is one line
    wide too when it runs that deep along less than `TWO_PASSES_SHARE` of that length."""
    arc = branch.arc
    length = arc[-1] - radius_a - radius_b
    if length < 4.0 * line:
        return False
    beyond = (arc > radius_a) & (arc < arc[-1] - radius_b)
    if not beyond.any():
        return False
    deep = branch.radii > TWO_PASSES_RADIUS * line
    if not deep[beyond].any():
        return True
    # Far apart, a crossing's halves are joined by the two passes parting steadily: their
    # centre lines are more than a fifth of a width apart, the ink more than 1.2 line radii
    # deep, along most of the way. A touch or a blot beside one line deepens it locally.
    inner = np.clip(arc, radius_a, arc[-1] - radius_b)
    steps = np.diff(inner)
    deep_length = float(steps[(deep[:-1] & deep[1:])].sum()) + 0.5 * float(steps[deep[:-1] ^ deep[1:]].sum())
    return length >= LONG_BRANCH_RADII * line and deep_length < TWO_PASSES_SHARE * length


def _min_radius(branch: Branch) -> float:
    inner = branch.radii[1:-1]
    return float(inner.min()) if inner.size else float(branch.radii.min())


def _merge(graph: MedialGraph, a: int, b: int, bid: int) -> int:
    """Replace nodes a, b and their joining branch by one node at the branch's middle."""
    join = graph.remove_branch(bid).oriented_from(a)
    arc = join.arc
    mid = int(np.searchsorted(arc, arc[-1] / 2.0))
    mid = min(max(mid, 0), len(arc) - 1)
    node = graph.add_node(join.points[mid], float(join.radii.max()))
    graph.spans[node] = float(arc[-1] / 2.0)
    # Each remaining branch keeps its geometry: it now starts at the middle node and runs
    # along the half of the joining branch that leads to its old junction.
    for old, half_points, half_radii, half_sins in (
        (a, join.points[: mid + 1][::-1], join.radii[: mid + 1][::-1], join.sins[:mid][::-1]),
        (b, join.points[mid:], join.radii[mid:], join.sins[mid:]),
    ):
        for other in dict.fromkeys(graph.incident[old]):  # a loop is listed twice
            branch = graph.remove_branch(other)
            if branch.a == branch.b:
                # A loop at the old junction: both of its ends move to the new node.
                pts = np.vstack([half_points, branch.points[1:], half_points[::-1][1:]])
                rad = np.concatenate([half_radii, branch.radii[1:], half_radii[::-1][1:]])
                sn = np.concatenate([half_sins, branch.sins, half_sins[::-1]])
                graph.add_branch(Branch(node, node, pts, rad, sn))
                continue
            out = branch.oriented_from(old)
            graph.add_branch(Branch(node, out.b, np.vstack([half_points, out.points[1:]]),
                                    np.concatenate([half_radii, out.radii[1:]]),
                                    np.concatenate([half_sins, out.sins])))
        del graph.incident[old], graph.positions[old], graph.radii[old]
    return node


# Two junctions closer than this (stroke widths) are one Voronoi vertex split in two: the
# junction-to-junction branches of 32 drawings (cursive, plain, handwriting, Hershey) are
# 0.012 and 0.013 w, then 0.099 w and longer.
SPLIT_VERTEX = 0.05


def _merge_split_vertices(graph: MedialGraph, stroke_width: float, through: dict, may_merge) -> int:
    """Merge each pair of degree-3 nodes joined by a branch shorter than SPLIT_VERTEX widths
    into one degree-4 node, in place; returns how many.

    Where four arms of the medial axis meet (an X of ink) and their outline samples lie
    nearly on one circle, qhull returns two vertices a hair apart, and which two arms each
    one holds depends on how the outline happened to be sampled. The merge rules of
    `simplify` read the arms' angles at each vertex, so they would merge such a pair or not
    by chance: it is one junction, and is merged before them.
    """
    merged = 0
    while True:
        pair = next(((b.a, b.b, bid) for bid, b in graph.branches.items()
                     if b.a != b.b and b.length < SPLIT_VERTEX * stroke_width
                     and graph.degree(b.a) == 3 and graph.degree(b.b) == 3
                     and b.a not in through and b.b not in through
                     and (may_merge is None or may_merge(b))), None)
        if pair is None:
            return merged
        _merge(graph, *pair)
        merged += 1


def simplify(graph: MedialGraph, *, stroke_width: float, multi: bool, ends: int = 2,
             may_merge=None, after_merging=None, through: dict | None = None) -> Simplified:
    """Merge crossing halves into degree-4 nodes in place and classify the other nodes.

    ends: free ends the single line is taken to have (2 open, 0 closed); free ends beyond
    those may be read as spikes drawn out and back. The user's edits hook in here
    (`vectorize.refine.refine`): may_merge(branch) -> False keeps the two nodes it joins apart (a
    split); after_merging(graph) makes the user's own merges before the nodes are typed.
    through: nodes already resolved as three passes crossing (`vectorize.axis.clusters`) -> their
    slot pairs; they are kept as they are.
    """
    through = dict(through or {})
    reach = 2.5 * stroke_width
    merged = _merge_split_vertices(graph, stroke_width, through, may_merge)
    line = line_radius(graph)

    def spike_slot(node: int) -> int | None:
        """Slot of the branch drawn out and back at a degree-3 node, if it has one.

        A V-shaped spike (two sides at an acute angle, paper's Y-junction) has its free
        end on the foot. A spike retraced exactly over itself leaves a T: a branch to a
        free end across a straight line. In a single-line drawing that is a spike too
        (the pen cannot end there and go on); in multi mode it is a stroke ending on
        another (paper 4.5).
        """
        if graph.degree(node) != 3:
            return None
        if _v_spike(graph, node, reach):
            return foot_slot(directions(graph, node, reach))
        if multi or node not in t_spikes:
            return None
        stub = _t_stub(graph, node, reach, stroke_width)
        return stub[0] if stub is not None else None

    # Spikes off a line (a T: the line runs on straight past the stub; or a serif: the
    # line turns into one arm and retraces the other) are only plausible while the drawing
    # has more free ends than the line can have (`ends`): take the straightest first,
    # until that many remain.
    t_spikes: set[int] = set()
    if not multi:
        t_spikes = set(graph.incident)  # let spike_slot test the T shape of every node
        leaves = len(graph.nodes_of_degree(1))
        v_spikes = [n for n in graph.nodes_of_degree(3) if _v_spike(graph, n, reach)]
        def crossing_half(node: int) -> bool:
            # Another junction within a stroke width, or one that with this node forms a
            # crossing (`_crossing_halves`): two halves of one crossing, not a spike's base.
            return any(graph.branches[bid].length < stroke_width and graph.degree(graph.branches[bid].other(node)) == 3
                       or _crossing_halves(graph, node, bid, reach, stroke_width)
                       for bid in graph.incident[node] if graph.branches[bid].other(node) != node)

        shaped = sorted(((_t_stub(graph, n, reach, stroke_width)[1], n) for n in graph.nodes_of_degree(3)
                         if n not in v_spikes and not crossing_half(n) and spike_slot(n) is not None), reverse=True)
        room = max(0, leaves - len(v_spikes) - ends)
        t_spikes = {n for _, n in shaped[:room]}

    def candidates() -> list[int]:
        return sorted(n for n in graph.nodes_of_degree(3) if spike_slot(n) is None)

    def joining(node: int, other_ok) -> dict[str, int | None]:
        """This node's picks: by widest narrowest radius (paper) and by foot."""
        node_slots = slots(graph, node)
        options = [(bid, graph.branches[bid].other(node)) for bid, _ in node_slots
                   if graph.branches[bid].a != graph.branches[bid].b]
        # A crossing at angle a keeps its two lines' inks merged over about w / sin(a / 2):
        # 40 stroke widths admits crossings down to ~3 degrees.
        dirs = directions(graph, node, reach)
        index = {bid: i for i, (bid, _) in enumerate(node_slots)}

        def opens_a_v(bid: int) -> bool:
            # Half a crossing: the two other branches leave at the crossing's acute
            # angle. At a T (a stroke ending on a line) they are nearly straight.
            a, b = (i for i in range(3) if i != index[bid])
            return float(np.dot(dirs[a], dirs[b])) > np.cos(np.radians(CROSSING_HALF_MAX_ANGLE))

        options = [(bid, far) for bid, far in options if other_ok(far)
                   and graph.branches[bid].length < 40.0 * stroke_width and opens_a_v(bid)
                   and _facing(graph, node, far, bid, reach)
                   and not _one_pass_wide(graph.branches[bid], graph.radii[node], graph.radii[far], line)]
        widest = max(options, key=lambda o: _min_radius(graph.branches[o[0]]), default=None)
        foot_bid = node_slots[foot_slot(dirs)][0]
        foot = next((o for o in options if o[0] == foot_bid), None)
        return {"widest": widest, "foot": foot}

    # Rounds: mutual widest picks, then mutual feet; each round recomputes the picks.
    for rule in ("widest", "foot"):
        while True:
            pool = set(candidates())
            picks = {n: joining(n, lambda far: far in pool)[rule] for n in pool}
            pairs = sorted({tuple(sorted((n, p[1]))) + (p[0],) for n, p in picks.items()
                            if p is not None and picks.get(p[1]) is not None and picks[p[1]][0] == p[0]
                            and (may_merge is None or may_merge(graph.branches[p[0]]))})
            if not pairs:
                break
            done: set[int] = set()
            for a, b, bid in pairs:
                if a in done or b in done or bid not in graph.branches:
                    continue
                _merge(graph, a, b, bid)
                done |= {a, b}
                merged += 1
    # Remaining non-mutual picks over short branches (the paper's second pass).
    while True:
        pool = set(candidates())
        progress = False
        for node in sorted(pool):
            if node not in graph.incident or graph.degree(node) != 3:
                continue
            pick = joining(node, lambda far: far in pool and far in graph.incident and graph.degree(far) == 3)["widest"]
            if pick is None or graph.branches[pick[0]].length > 2.0 * stroke_width:
                continue
            if may_merge is not None and not may_merge(graph.branches[pick[0]]):
                continue
            _merge(graph, node, pick[1], pick[0])
            pool -= {node, pick[1]}
            merged += 1
            progress = True
        if not progress:
            break

    if after_merging is not None:
        merged += after_merging(graph)
    y_feet, y_tips, t_ends, unresolved, retraced = {}, set(), [], [], set()
    for node in sorted(graph.incident):
        degree = graph.degree(node)
        if degree == 3:
            node_slots = slots(graph, node)
            dirs = directions(graph, node, reach)
            spike = spike_slot(node)
            if spike is not None:
                y_feet[node] = spike
                if not _v_spike(graph, node, reach):
                    retraced.add(node)  # a T: the spike runs back over itself
                y_tips.add(graph.branches[node_slots[spike][0]].other(node))
            elif is_t_shape(dirs):
                # A stroke ending on another line: an end of the drawing (paper 3.3, 4.5).
                t_ends.append(node)
            else:
                # Three strokes seem to meet, or a crossing lost its other half. In
                # single-line mode it still counts as an end (paper 3.3); report it.
                unresolved.append(node)
                if not multi:
                    t_ends.append(node)
        elif degree >= 5 and node not in through:
            unresolved.append(node)
    crossings = tuple(sorted(graph.nodes_of_degree(4)))
    return Simplified(y_feet, frozenset(y_tips), crossings, merged, tuple(unresolved), tuple(t_ends),
                      frozenset(retraced), through)


def is_t_shape(dirs: np.ndarray) -> bool:
    """Largest angle between branches near 180 degrees and the other two alike (paper 4.5)."""
    pairs = [(0, 1), (0, 2), (1, 2)]
    angles = sorted(float(np.degrees(np.arccos(np.clip(np.dot(dirs[i], dirs[j]), -1, 1)))) for i, j in pairs)
    return angles[2] > 150.0 and abs(angles[1] - angles[0]) < 40.0


# At half a crossing the two branches other than the joining one meet at the crossing's
# acute angle (<= 90 degrees, plus measuring noise).
CROSSING_HALF_MAX_ANGLE = 125.0
# The two sides of a V-shaped spike leave its junction at an acute angle; a T (90 degrees
# each way) would otherwise pass the paper's foot test by a coin toss.
V_SPIKE_MAX_ANGLE = 75.0


def _opening(graph: MedialGraph, node: int, bid: int, reach: float) -> np.ndarray:
    """The sum of the unit tangents at `node` of its branch ends other than branch `bid`'s."""
    dirs = directions(graph, node, reach)
    return sum((d for (b, _), d in zip(slots(graph, node), dirs) if b != bid), np.zeros(2))


def _facing(graph: MedialGraph, node: int, other: int, bid: int, reach: float) -> bool:
    """Whether the junctions `node` and `other`, joined by branch `bid`, open away from each
    other, as the two halves of a crossing do: each pass runs in at one and out at the other,
    bending less than a right angle across the pair. Two forks whose branches leave the same
    way (a u's arm and the next letter's stem, both rising from the line between them) are two
    junctions of the line: a pass from one to the other would turn back."""
    return float(np.dot(_opening(graph, node, bid, reach), _opening(graph, other, bid, reach))) < 0.0


def _v_spike(graph: MedialGraph, node: int, reach: float) -> bool:
    """The paper's Y-junction: the foot of a degree-3 node (opposite its smallest angle,
    which must be acute) ends in a free end."""
    dirs = directions(graph, node, reach)
    foot = foot_slot(dirs)
    sides = [i for i in range(3) if i != foot]
    if float(np.dot(dirs[sides[0]], dirs[sides[1]])) < np.cos(np.radians(V_SPIKE_MAX_ANGLE)):
        return False
    return graph.degree(graph.branches[slots(graph, node)[foot][0]].other(node)) == 1


def _crossing_halves(graph: MedialGraph, node: int, bid: int, reach: float, stroke_width: float) -> bool:
    """Whether `node` and the degree-3 junction at the other end of branch `bid` are the two
    halves of one crossing: the two passes run straight through both junctions (each bends
    by at most `CROSSING_PASS_MAX_BEND`, `CROSSING_LOOP_MAX_BEND` where they close a loop),
    the branch between them is the widest at `node`, and it is no longer than the ink two
    lines crossing at that angle share ((w + `CROSSING_EDGE_BLUR`) / sin(a / 2), a the angle
    between the passes, with `CROSSING_JOIN_SLACK`).

    Where a crossing lies a few widths from the line's end (a loop's exit stroke crossing
    its way in: the last letter's loop, an e at a word's end), the short exit ends free
    and reads like a spike off a straight line (a T) unless the crossing is seen whole. So
    does a stem drawn down through a crossing and back up (an h's or l's stem below the
    point where its ascender loop crosses the way in): it is a spike, but its base is a
    crossing's too, and the route retraces it through the crossing (`route.retrace_paths`
    may turn there at a price).
    """
    other = graph.branches[bid].other(node)
    if other == node or graph.degree(other) != 3:
        return False
    # The two passes close a loop through the pair when one junction's two other branches
    # end at one node (a loop's two ends, or a loop through the next junction: an h's loop
    # where its arch leaves). Such a junction cannot be resolved alone: a loop is entered
    # and left at a crossing or touch.
    closes_loop = any(len({graph.branches[b].other(end) for b in graph.incident[end] if b != bid}) == 1
                      for end in (node, other))
    legs = []
    for end in (node, other):
        end_slots = slots(graph, end)
        dirs = directions(graph, end, reach)
        link = [i for i, (b, _) in enumerate(end_slots) if b == bid]
        legs.append([dirs[i] for i in range(3) if i != link[0]])
    (a0, a1), (b0, b1) = legs
    # A pass enters along -a and leaves along b: straight when a and b are opposite.
    straight, crossed = max(float(np.dot(a0, b0)), float(np.dot(a1, b1))), max(float(np.dot(a0, b1)), float(np.dot(a1, b0)))
    bend = min(straight, crossed)
    if bend > -np.cos(np.radians(CROSSING_LOOP_MAX_BEND if closes_loop else CROSSING_PASS_MAX_BEND)):
        return False
    # The branch between the halves runs through ink laid down twice: the widest (paper, Fig. 4).
    link = _min_radius(graph.branches[bid])
    if any(_min_radius(graph.branches[b]) > link for b in graph.incident[node] if b != bid):
        return False
    # The angle between the two passes, each pass's heading taken across the pair (in along
    # -a, out along the b it pairs with): the same from either junction. Each junction's own
    # legs alone measure it differently (a y loop crossing its exit stroke, 6.7 px between the
    # halves: 55 degrees at the loop's junction, 70 at the exit's), so the pair was a crossing
    # seen from one half and a spike's base from the other.
    (b0, b1) = (b0, b1) if straight <= crossed else (b1, b0)
    pass0, pass1 = b0 - a0, b1 - a1
    cos = float(np.dot(pass0, pass1)) / max(float(np.linalg.norm(pass0) * np.linalg.norm(pass1)), 1e-9)
    half_angle = 0.5 * np.arccos(np.clip(cos, -1.0, 1.0))
    shared = (stroke_width + CROSSING_EDGE_BLUR) / max(np.sin(half_angle), 1e-3)
    return graph.branches[bid].length <= CROSSING_JOIN_SLACK * shared


# Each of the two passes through a crossing seen as two junctions bends by less than this
# (degrees) across the pair; a spike's base next to another junction does not continue
# straight into one of its branches.
CROSSING_PASS_MAX_BEND = 30.0
# ... and by less than this where they close a loop: a cursive e's way in bends into its
# loop (21-43 degrees measured over 2.5 widths on the cursive set's e's).
CROSSING_LOOP_MAX_BEND = 45.0
# The measured stroke width falls short of the ink's (anti-aliased edges) and the branches'
# directions, measured a few widths out, open wider than the crossing itself: slack on the
# shared ink's length w / sin(a / 2).
CROSSING_JOIN_SLACK = 1.5
# px added to the measured width for the shared ink: where two lines overlap, their
# anti-aliased edges add their grey, and the ink passes the threshold up to half a pixel
# further out on each side than along one line (lines 2-2.5 px wide measure 1.5 px).
CROSSING_EDGE_BLUR = 1.0


def _t_stub(graph: MedialGraph, node: int, reach: float, stroke_width: float) -> tuple[int, float] | None:
    """The free branch of a degree-3 node that leaves the straightest line behind, and how
    straight that line is (-cos of the angle between the two other branches); None when
    no branch longer than a stroke width ends free."""
    node_slots = slots(graph, node)
    dirs = directions(graph, node, reach)
    stubs = [i for i, (bid, _) in enumerate(node_slots)
             if graph.degree(graph.branches[bid].other(node)) == 1 and graph.branches[bid].length > stroke_width]

    def straightness(stub: int) -> float:
        a, b = (i for i in range(3) if i != stub)
        return -float(np.dot(dirs[a], dirs[b]))

    if not stubs:
        return None
    stub = max(stubs, key=straightness)
    return stub, straightness(stub)
