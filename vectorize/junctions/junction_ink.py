"""A junction's own ink: its strokes' medial axis out to some widths of line, as discs.

The crossing CNN judges a junction from two crops, the far one 32 stroke widths wide. In
cursive that crop holds whole letters beside the junction (the next loop, a neighbouring
stem), and the shipped model, trained on lone strokes, reads such crowded crossings as
touches: at the cursive benchmark's 704 ground-truth crossings it is right on 322 with the
whole word drawn and on 98 % with only about 6 widths of line drawn around each pass
(docs/classifier.md, "Cursive shapes"). So the classifier is shown the ink of the
junction's own strokes only: the medial-axis points within a few widths of arc length of
the node, each a disc of its local radius; the image is masked to those discs
(`vectorize.junctions.junction_crop.masked_window`).
"""

from __future__ import annotations

import numpy as np

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import slot_direction, slots
from vectorize.junctions.intersections import crossing_pairing

# Arc length of line kept around a junction, in stroke widths (each branch, measured from
# the end of the ink the junction's passes share): SEPARATION / sin(angle between the two
# straight-through passes), within [MIN_REACH, MAX_REACH]. Two strokes crossing at 30
# degrees need ~10 w of line to show that they part; steep crossings are read best with
# 4-8 w, and with 12-15 w the next letters come back into view. Measured on the cursive
# and touch sets: docs/classifier.md, "Only the junction's own ink".
SEPARATION, MIN_REACH, MAX_REACH = 5.0, 6.0, 10.0


def own_ink_reach(directions: np.ndarray, stroke_width: float) -> float:
    """Arc length (px) of line to keep around a junction with unit branch directions
    (4, 2): the shallower the crossing of the straight-through passes, the more."""
    (a, b), (c, e) = crossing_pairing(directions)
    u, v = directions[a] - directions[b], directions[c] - directions[e]
    sine = abs(float(u[0] * v[1] - u[1] * v[0])) / max(float(np.hypot(*u) * np.hypot(*v)), 1e-9)
    return float(np.clip(SEPARATION / max(sine, 1e-3), MIN_REACH, MAX_REACH)) * stroke_width


def own_ink(graph: MedialGraph, node: int, reach: float, stroke_width: float) -> np.ndarray:
    """(K, 3) x, y, radius (px) of the medial-axis points within `reach` px of arc length
    of `node` (plus the node's merged span, `graph.spans`), the node first.

    Each branch is followed out of the node; where it ends at another node with length to
    spare, the line goes on along the branch that continues it most straightly (the pen's
    likeliest way; the other strokes meeting there, an h's stem beside its loop's
    crossing, are not this junction's ink). Branch directions are read 2.5 stroke widths
    out, as for the junctions.
    """
    parts = [np.array([[*graph.positions[node], graph.radii[node]]])]
    budget = reach + graph.spans.get(node, 0.0)
    turn = 2.5 * stroke_width
    for slot in slots(graph, node):
        left, steps = budget, 0
        while left > 0 and steps < 16:  # steps: a bound on a walk round tiny loops
            bid, end = slot
            branch = graph.branches[bid]
            points, radii, arc = ((branch.points, branch.radii, branch.arc) if end == "a" else
                                  (branch.points[::-1], branch.radii[::-1], branch.arc_back))
            inside = arc <= left
            parts.append(np.column_stack([points[inside], radii[inside]]))
            left -= branch.length
            steps += 1
            far = branch.node("b" if end == "a" else "a")
            if left <= 0 or far == node:
                break
            back = (bid, "b" if end == "a" else "a")  # the same branch, leaving `far`
            others = [s for s in slots(graph, far) if s != back]
            if not others:
                break
            came = slot_direction(graph, back, turn)
            slot = min(others, key=lambda s: float(np.dot(came, slot_direction(graph, s, turn))))
    return np.concatenate(parts)
