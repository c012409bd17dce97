"""Pruning noise branches of the medial axis (vanishing-angle pruning, Rong & Ju 2023).

A leaf branch is noise when the outline samples that generate it sit on the same side of
the ink (a bump, a corner of a square stroke end): its object angle is small, so the
length-weighted mean of sin(object angle) falls below a threshold. Real tubes have angles
near 90 degrees and survive, however short. Pruning repeats until nothing changes,
because removing spurs turns junctions into degree-2 points and exposes new leaves.
"""

from __future__ import annotations

import numpy as np

from vectorize.axis.graph import MedialGraph, measure_short

# A leaf that runs on more than this many stroke widths beyond its junction's disc, mostly
# as a tube, is a stroke's end, whatever its mean object angle. Thick strokes need this:
# their ragged outlines grow a spur every pixel or two, and once those are pruned the
# spurs and the round cap that merge into the end dilute its significance below the
# threshold, which then ate 5-width tails whole.
TUBE_REACH, TUBE_SIGNIFICANCE = 1.5, 0.5


def prune(graph: MedialGraph, *, threshold: float, stroke_width: float) -> int:
    """Remove noise leaf branches in place; returns how many branches were removed.

    A leaf branch (one end of degree 1, the other a junction) goes when its vanishing-angle
    significance is below `threshold`, or when it hardly leaves the junction's disc (its
    length is under the junction radius plus a quarter stroke width). Long tubes stay.
    """
    removed = 0
    incident, radii = graph.incident, graph.radii
    while True:
        # Only a branch at a free end can be a spur: the others are not looked at.
        leaves = {bid: graph.branches[bid] for bid in sorted({inc[0] for inc in incident.values() if len(inc) == 1})}
        measure_short(list(leaves.values()))
        doomed = []
        for bid, branch in leaves.items():
            a, b = branch.a, branch.b
            leaf_a, leaf_b = len(incident[a]) == 1, len(incident[b]) == 1
            if a == b or leaf_a == leaf_b:
                continue  # loops, whole isolated strokes, and inner branches stay
            junction = b if leaf_a else a
            reach = branch.length - radii[junction]  # how far it leaves the junction's disc
            significance = branch.significance
            if reach > TUBE_REACH * stroke_width and significance > TUBE_SIGNIFICANCE:
                continue  # a stroke's real end (see TUBE_REACH)
            short = reach < 0.25 * stroke_width
            if short or significance < threshold:
                doomed.append((significance, bid))
        if not doomed:
            break
        # Remove the least significant spur at each junction first: two spurs of one
        # junction may be its two real arms after all (e.g. a sharp V tip).
        seen: set[int] = set()
        for _, bid in sorted(doomed):
            branch = graph.branches.get(bid)
            if branch is None:
                continue
            leaf = branch.a if graph.degree(branch.a) == 1 else branch.b
            junction = branch.other(leaf)
            if junction in seen or graph.degree(junction) < 3:
                continue
            seen.add(junction)
            graph.remove_node(leaf)
            removed += 1
        if not seen:
            break
        graph.dissolve_degree_two()
    # Drop isolated specks of axis (no junction, shorter than a stroke width).
    for bid, branch in list(graph.branches.items()):
        if graph.degree(branch.a) == 1 and graph.degree(branch.b) == 1 and branch.length < stroke_width * 0.5:
            if len(graph.branches) > 1:
                graph.remove_node(branch.a)
                graph.remove_node(branch.b)
                removed += 1
    return removed


def trim_free_ends(graph: MedialGraph, *, stroke_width: float) -> None:
    """Pull each free end back to its cap centre, in place.

    The medial axis of a round stroke end ends at the centre of the cap; sampled outlines
    let it run on towards the tip with shrinking radius, which would make the stroke
    longer than the line drawn. Cut the end where the radius falls below 85 % of the
    radius one stroke width further in.
    """
    from vectorize.axis.graph import Branch

    for node in [n for n, inc in graph.incident.items() if len(inc) == 1]:
        bid = graph.incident[node][0]
        branch = graph.branches[bid]
        if branch.a == branch.b:
            continue
        out = branch.oriented_from(node)
        arc = out.arc
        # The radius one stroke width in: past the cap, before any widening further on
        # (a spike's two sides merge into wider ink towards its junction).
        band = out.radii[(arc >= 0.6 * stroke_width) & (arc <= 1.4 * stroke_width)]
        if band.size < 3:
            continue
        # Not more than the drawing's own half width: where the ink widens inwards (the foot
        # of a sharp V, both sides' inks merged) the end already is the cap's centre.
        full = 0.85 * min(float(np.median(band)), 0.5 * stroke_width)
        first = int(np.argmax(out.radii >= full))
        if first == 0 or arc[first] > stroke_width or first >= len(out.points) - 2:
            continue
        graph.remove_branch(bid)
        graph.positions[node] = out.points[first].copy()
        graph.radii[node] = float(out.radii[first])
        trimmed = Branch(node, out.b, out.points[first:], out.radii[first:], out.sins[first:])
        graph.add_branch(trimmed)
