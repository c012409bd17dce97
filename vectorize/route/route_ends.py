"""Where a single line may start and end: the cost (px) of each node as one of its two ends,
the weights route inspection's matching gives its end vertices (`route_matching`).

A free end costs nothing. The tip of a sharp corner's spur (a V drawn out and back whose
sides merge) is a poor place to start, a junction a poorer one, except where a line comes in
and stops on another (a T whose stem is not a free branch: the tail of a 6 closing its loop).
Each is worth a retrace of up to its cost to avoid, but never more than `END_SHARE` of the
whole line per end.
"""

from __future__ import annotations

import numpy as np

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import Simplified, is_t_shape, slots

# Cost (in stroke widths) of the pen starting or ending at a junction that is not a line
# ending on another line: a whole spike of up to this length is retraced rather.
JUNCTION_END = 20.0
CORNER_TIP_END = 3.0  # widths: the tip of a sharp corner's spur
T_STEM_END = 0.1  # widths: a line that stops on another
# ... but never more than this share of the whole line per end: avoiding a poor end is not
# worth drawing more than 1 % of the drawing twice (a long spike on a closed loop then starts
# at its tip and ends at its base, the shortest line over the ink).
END_SHARE = 0.01


def end_costs(graph: MedialGraph, simple: Simplified, directions: dict, stroke_width: float) -> dict[int, float]:
    """node -> cost (px) of the line starting or ending there (nodes left out cost nothing).

    directions: node -> (D, 2) unit tangents per slot, for the nodes of degree >= 3.
    """
    w = stroke_width
    tips = {graph.branches[slots(graph, n)[f][0]].other(n) for n, f in simple.y_feet.items()
            if n not in simple.retraced}
    cost = {n: CORNER_TIP_END * w for n in tips}
    cost.update({n: _junction_end(graph, n, directions[n], w) for n in directions})
    most = END_SHARE * sum(b.length for b in graph.branches.values())
    return {n: min(c, most) for n, c in cost.items()}


def _junction_end(graph: MedialGraph, node: int, dirs: np.ndarray, w: float) -> float:
    """How poor a place junction `node` is for the pen to start or end (px): plausible only
    where a line comes in and stops on another; where a stub or spike leaves a line the pen
    would have drawn the stub first from its far end."""
    if len(dirs) == 3 and is_t_shape(dirs):
        cos = [(float(np.dot(dirs[i], dirs[j])), k) for i, j, k in ((0, 1, 2), (0, 2, 1), (1, 2, 0))]
        stem = min(cos)[1]
        if graph.degree(graph.branches[slots(graph, node)[stem][0]].other(node)) != 1:
            return T_STEM_END * w
    return JUNCTION_END * w
