"""Pruning noise branches of the medial axis (vanishing-angle pruning, Rong & Ju 2023).

A leaf branch is noise when the outline samples that generate it sit on the same side of
the ink (a bump, a corner of a square stroke end): its object angle is small, so the
length-weighted mean of sin(object angle) falls below a threshold. Real tubes have angles
near 90 degrees and survive, however short. Pruning repeats until nothing changes,
because removing spurs turns junctions into degree-2 points and exposes new leaves.
"""

from __future__ import annotations

from vectorize.graph import MedialGraph


def prune(graph: MedialGraph, *, threshold: float, stroke_width: float) -> int:
    """Remove noise leaf branches in place; returns how many branches were removed.

    A leaf branch (one end of degree 1, the other a junction) goes when its vanishing-angle
    significance is below `threshold`, or when it hardly leaves the junction's disc (its
    length is under the junction radius plus a quarter stroke width).
    """
    removed = 0
    while True:
        doomed = []
        for bid, branch in graph.branches.items():
            da, db = graph.degree(branch.a), graph.degree(branch.b)
            if branch.a == branch.b or (da == 1) == (db == 1):
                continue  # loops, whole isolated strokes, and inner branches stay
            junction = branch.b if da == 1 else branch.a
            short = branch.length < graph.radii[junction] + 0.25 * stroke_width
            if short or branch.significance < threshold:
                doomed.append((branch.significance, bid))
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
