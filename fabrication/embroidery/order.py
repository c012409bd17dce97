"""Sewing order: threads per stroke, one colour block per thread, and where sewing starts.

The drawing order is the artist's order and stays the order within a colour. Strokes of
one colour are sewn together (one colour block each); the next block is the one whose
first stroke starts nearest to where the last block ended, so jumps between blocks stay
short. `start` picks where sewing begins: 'reverse' sews the whole drawing backwards, a
point (x, y) in mm (the placed design's frame: centred on (0, 0), x right, y down) starts
on the curve nearest to it (a closed stroke is opened there, an open one is sewn from its
nearer end).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.thread import RGB, Thread, nearest_thread
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke, recut_widths

Start = str | tuple[float, float] | None


def check_start(start: Start) -> Start:
    """`start` as given if valid: None, 'reverse' or two finite numbers (mm)."""
    if start is None or start == "reverse":
        return start
    if isinstance(start, str):
        raise InputError(f"start {start!r} must be 'reverse' or a point X,Y in mm")
    try:
        x, y = (float(v) for v in start)
    except (TypeError, ValueError):
        raise InputError(f"start {start!r} must be 'reverse' or a point X,Y in mm") from None
    if not (np.isfinite(x) and np.isfinite(y)):
        raise InputError(f"start point {start!r} must be finite numbers in mm")
    return (x, y)


def parse_start(text: str) -> Start:
    """'reverse' or 'X,Y' (mm, units allowed: '10mm,-5mm') from the command line."""
    from onestroke.units import parse_length

    value = str(text).strip().lower()
    if value == "reverse":
        return "reverse"
    parts = value.split(",")
    if len(parts) != 2:
        raise InputError(f"--start {text!r} must be 'reverse' or a point X,Y in mm from the "
                         "design centre (e.g. 0,-20)")
    return check_start(tuple(parse_length(p, what="--start") for p in parts))


def stroke_colors(drawing: Drawing, colors: tuple[RGB, ...], default: RGB) -> list[RGB]:
    """The thread colour of each stroke: `colors[i]` when given (the last one repeats for
    strokes beyond the list), else the stroke's own colour, else `default`."""
    if colors:
        return [tuple(colors[min(i, len(colors) - 1)]) for i in range(len(drawing.strokes))]
    return [tuple(s.color) if s.color is not None else tuple(default) for s in drawing.strokes]


def _split_cubic(control: np.ndarray, u: float) -> tuple[np.ndarray, np.ndarray]:
    """De Casteljau: one cubic (4, 2) cut at local parameter u into two (4, 2)."""
    p01, p12, p23 = (control[:-1] * (1 - u) + control[1:] * u)
    a, b = p01 * (1 - u) + p12 * u, p12 * (1 - u) + p23 * u
    m = a * (1 - u) + b * u
    return np.array([control[0], p01, a, m]), np.array([m, b, p23, control[3]])


def _open_at(stroke: Stroke, t: float) -> Stroke:
    """A closed stroke re-started at global parameter t (same curve, same direction)."""
    k = min(int(t * stroke.segment_count), stroke.segment_count - 1)
    u = t * stroke.segment_count - k
    c = stroke.control
    n = len(c)
    if u < 1e-6 or u > 1 - 1e-6:
        k = (k + 1) % n if u > 0.5 else k
        widths = recut_widths(stroke.widths, np.array([k, k + n]) / n, np.array([0.0, 1.0]))
        return Stroke(np.concatenate([c[k:], c[:k]]), stroke.color, widths)
    first, second = _split_cubic(c[k], u)
    # new segment j runs over old parameters k + u, k + 1, ..., k + n, k + n + u (over n)
    old = np.concatenate([[k + u], np.arange(k + 1, k + n + 1), [k + n + u]]) / n
    widths = recut_widths(stroke.widths, old, np.linspace(0.0, 1.0, n + 2))
    return Stroke(np.concatenate([second[None], c[k + 1:], c[:k], first[None]]), stroke.color, widths)


def _nearest_on_curve(strokes: tuple[Stroke, ...], point: np.ndarray) -> tuple[int, float]:
    """(stroke index, parameter t) of the curve point nearest to `point` (to 0.05 mm)."""
    best = (0, 0.0, np.inf)
    for index, stroke in enumerate(strokes):
        n = max(8, int(np.ceil(stroke.length / 0.05)))
        t = np.linspace(0.0, 1.0, n + 1)
        d = np.linalg.norm(stroke.points_at(t) - point, axis=1)
        j = int(np.argmin(d))
        if d[j] < best[2]:
            best = (index, float(t[j]), float(d[j]))
    return best[0], best[1]


@dataclass(frozen=True, eq=False)
class SewingOrder:
    """drawing: the strokes as they will be sewn (reordered, maybe reversed or opened
    elsewhere); source: index of each in the input drawing; threads: one per colour block,
    in sewing order; block: colour block of each sewn stroke."""

    drawing: Drawing
    source: tuple[int, ...]
    threads: tuple[Thread, ...]
    block: tuple[int, ...]


def sewing_order(drawing: Drawing, *, colors: tuple[RGB, ...] = (), default: RGB = (0, 0, 0),
                 start: Start = None, thread_chart: str | None = None) -> SewingOrder:
    """Order `drawing`'s strokes for sewing: colour blocks, short jumps, the chosen start."""
    start = check_start(start)
    strokes = list(drawing.strokes)
    source = list(range(len(strokes)))
    rgb = stroke_colors(drawing, colors, default)
    if start == "reverse":
        strokes, source, rgb = [s.reversed() for s in strokes[::-1]], source[::-1], rgb[::-1]
    elif start is not None:
        index, t = _nearest_on_curve(tuple(strokes), np.asarray(start, dtype=float))
        stroke = strokes[index]
        if stroke.is_closed:
            stroke = _open_at(stroke, t)
        elif t > 0.5:
            stroke = stroke.reversed()
        # The chosen stroke first; the others keep their drawing order after it.
        rest = list(range(index + 1, len(strokes))) + list(range(index))
        strokes = [stroke] + [strokes[i] for i in rest]
        source = [source[index]] + [source[i] for i in rest]
        rgb = [rgb[index]] + [rgb[i] for i in rest]
    # Threads in order of first appearance; a chart maps each colour to its nearest thread.
    palette: list[RGB] = []
    for c in rgb:
        if c not in palette:
            palette.append(c)
    members = {c: [i for i in range(len(strokes)) if rgb[i] == c] for c in palette}
    order: list[int] = []
    blocks: list[RGB] = []
    remaining = list(palette)
    position = None
    while remaining:
        if position is None:
            chosen = remaining[0]
        else:
            gaps = [np.linalg.norm(strokes[members[c][0]].start - position) for c in remaining]
            chosen = remaining[int(np.argmin(gaps))]  # ties: the earlier colour
        remaining.remove(chosen)
        order += members[chosen]
        blocks.append(chosen)
        position = strokes[members[chosen][-1]].end
    threads = tuple(nearest_thread(c, thread_chart) if thread_chart else Thread(color=c) for c in blocks)
    block_of = {c: k for k, c in enumerate(blocks)}
    # The same stroke objects (their cached arc-length tables with them); threads are
    # looked up through `block`.
    sewn = tuple(strokes[i] for i in order)
    return SewingOrder(drawing=drawing.with_strokes(sewn), source=tuple(source[i] for i in order),
                       threads=threads, block=tuple(block_of[rgb[i]] for i in order))
