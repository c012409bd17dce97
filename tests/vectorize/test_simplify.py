"""Simplification's node types on constructed drawings (`vectorize.axis.simplify`)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from tests.drawings import render_polylines
from vectorize import VectorizeOptions, vectorize_image
from vectorize.axis.simplify import simplify


def _loop_with_short_tails(tail: float) -> tuple[np.ndarray, np.ndarray]:
    """A trochoid loop whose two ends run `tail` (curve parameter) past its crossing at
    about 50 degrees, as a word's last e or y loop crosses its way in a few widths before
    the line ends: (points (N, 2) px, the crossing (2,) px)."""
    t0 = brentq(lambda t: 20.0 * t - 110.0 * np.sin(t), 1.0, 3.1)
    t = np.linspace(-t0 - tail, t0 + tail, 600)
    return np.c_[250 + 20.0 * t - 110.0 * np.sin(t), 200 - 110.0 * np.cos(t)], np.array([250.0, 200 - 110.0 * np.cos(t0)])


@pytest.mark.parametrize("tail, width", [(0.2, 3.0), (0.35, 3.0), (0.2, 6.0), (0.35, 6.0)])
def test_a_crossing_next_to_the_line_end_is_a_crossing_not_a_spike(tail, width):
    """The short tail beyond the crossing ends free beside a junction whose other two
    branches run on nearly straight: alone, that junction looks like a spike's base (a T).
    With free ends to spare (a cursive line has dozens: hooks, entry stubs, stems drawn up
    and back; here the closed reading, ends=0, where every free end may be a spike), the
    two junctions must still be seen as one crossing, the passes straight through both.
    Tails of 25-45 px, 4-15 widths."""
    line, crossing = _loop_with_short_tails(tail)
    stages = vectorize_image(render_polylines([line], size=(500, 360), width=width),
                             VectorizeOptions(keep_stages=True)).stages
    graph = stages["pruned"].copy()
    simple = simplify(graph, stroke_width=stages["ink"].stroke_width, multi=False, ends=0)
    near = [n for n in simple.crossings if np.linalg.norm(graph.positions[n] - crossing) < 2 * width]
    spikes = [n for n in simple.y_feet if np.linalg.norm(graph.positions[n] - crossing) < 4 * width]
    assert len(near) == 1 and not spikes
