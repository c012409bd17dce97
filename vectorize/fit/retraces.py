"""Retraced stretches are one line drawn twice: both passes get the same fitted curve.

Where the route draws a stretch of the centre line twice (a stem down and back up, a
crossbar out and back, a path route inspection repeats between two junctions), the two
passes lie on the same ink. Fitted separately they differ by the fit's own noise (a few
tenths of a pixel, more with hand jitter in the centre line) and so cross each other
back and forth all along the stretch: a string of crossings that are not in the drawing,
and two slightly different lines where the pen drew one. Instead the stretch is cut out
at its two ends, fitted once, and the second pass is that curve (reversed when the pen
comes back the other way). Crossings are then only where passes really cross.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import directions, slots


@dataclass(frozen=True)
class Twin:
    """Two ranges of a traced stroke's points (inclusive indices) over the same centre line.

    first: (lo, hi) of the earlier pass; second: (lo, hi) of the later one; reverse: the
    later pass runs the other way (point second.lo is point first.hi).
    """

    first: tuple[int, int]
    second: tuple[int, int]
    reverse: bool

    def mirror(self, j: int) -> int:
        """Index in `second` of point j of `first`."""
        lo1, hi1 = self.first
        return self.second[0] + (hi1 - j if self.reverse else j - lo1)


def foot_is_retraced(graph: MedialGraph, node: int, foot: int, stroke_width: float) -> bool:
    """Whether the foot of a V-spike at `node` (slot `foot`) is a stretch drawn twice.

    Two lines of width w meeting at an angle a share their ink for w / (2 sin(a / 2))
    from the apex; that much of a foot is the corner itself, where the two sides merge
    and the pen turns (the sides are extended to the tip instead). A foot more than twice
    as long runs on beyond what the corner explains. It is a line drawn down and back up
    (a stem, a cusp drawn as a retrace), whose centre line both passes follow, when its
    ink does not widen towards the junction: two lines parting at any angle widen their
    shared ink from one width at the tip to two where they separate (the medial radius
    grows by w / 2 along the foot), one line drawn twice keeps its width. The foot's
    radius trend (least squares, a width clear of either end) is compared with both.
    """
    dirs = directions(graph, node, 2.5 * stroke_width)
    a, b = (i for i in range(3) if i != foot)
    half = 0.5 * float(np.arccos(np.clip(np.dot(dirs[a], dirs[b]), -1.0, 1.0)))
    merged = stroke_width / (2.0 * max(np.sin(half), 1e-3))
    branch = graph.branches[slots(graph, node)[foot][0]].oriented_from(node)
    arc = branch.arc
    if arc[-1] <= 2.0 * merged:
        return False
    inner = (arc > stroke_width) & (arc < arc[-1] - stroke_width)
    if inner.sum() < 3:
        return False
    # Radius lost from the junction to the tip: ~w / 2 for a V, ~0 for a retrace.
    growth = -float(np.polyfit(arc[inner], branch.radii[inner], 1)[0]) * arc[-1]
    return growth < stroke_width / 4.0


def retraced_runs(branches: Sequence[int], starts: Sequence[str],
                  exclude: set[int] = frozenset()) -> list[tuple[tuple[int, int], tuple[int, int], bool]]:
    """Runs of consecutive passes that the stroke makes twice.

    branches, starts: per pass, its branch id and the end it starts from. Returns
    ((first pass, last pass) of the earlier run, (first, last) of the later run, reverse)
    for maximal runs: a spike out and back is one run and its mirror, a path drawn twice
    in the same direction one run and its copy. Branches drawn more than twice, and those
    in `exclude`, are left alone.
    """
    where: dict[int, list[int]] = {}
    for k, b in enumerate(branches):
        where.setdefault(b, []).append(k)

    def partner(k: int) -> int | None:
        seen = where[branches[k]]
        return seen[1] if len(seen) == 2 and seen[0] == k and branches[k] not in exclude else None

    used: set[int] = set()
    runs = []
    for i in range(len(branches)):
        p = partner(i)
        if i in used or p is None:
            continue
        reverse = starts[i] != starts[p]
        step = -1 if reverse else 1
        k = 1
        while True:
            a, b = i + k, p + step * k
            if a >= len(branches) or not 0 <= b < len(branches) or (a >= b if reverse else a >= p):
                break
            if partner(a) != b or (starts[a] != starts[b]) != reverse:
                break
            k += 1
        later = (p - k + 1, p) if reverse else (p, p + k - 1)
        runs.append(((i, i + k - 1), later, reverse))
        used.update(range(i, i + k))
        used.update(range(later[0], later[1] + 1))
    return runs


def twin_spans(branches: Sequence[int], starts: Sequence[str], spans: Sequence[tuple[int, int]],
               exclude: set[int] = frozenset()) -> list[Twin]:
    """Retraced runs as ranges of traced points.

    spans: per pass, the (lo, hi) traced-point indices it covers (a pass shares its first
    point with the previous pass's last); exclude: branch ids whose runs are left alone.
    """
    twins = []
    for (a, b), (c, d), reverse in retraced_runs(branches, starts, exclude):
        twins.append(Twin((spans[a][0], spans[b][1]), (spans[c][0], spans[d][1]), reverse))
    return twins


def trimmed_twins(xy: np.ndarray, twins: Sequence[Twin], cuts: Sequence[int]) -> list[Twin]:
    """The twins cut to the points both ranges still hold where a pass was cut short at one of
    the point indices `cuts` (`route.traversal.half_turns`: a turn made where two branches
    part, not at the node): what matches from each of the twin's two ends on, as one or two
    twins. Twins over no cut are left as they are."""
    result = []
    for t in twins:
        (lo1, hi1), (lo2, hi2) = t.first, t.second
        if valid_twins(xy, [t]) or not any(lo1 <= c <= hi1 or lo2 <= c <= hi2 for c in cuts):
            result.append(t)
            continue
        # Point k from the later range's start is point a(k) of the earlier range; from its end, b(k).
        a = (lambda k: hi1 - k) if t.reverse else (lambda k: lo1 + k)
        b = (lambda k: lo1 + k) if t.reverse else (lambda k: hi1 - k)
        size = min(hi1 - lo1, hi2 - lo2) + 1
        head = next((k for k in range(size) if not np.array_equal(xy[lo2 + k], xy[a(k)])), size)
        tail = next((k for k in range(size - head) if not np.array_equal(xy[hi2 - k], xy[b(k)])), size - head)
        for second, one, two in (((lo2, lo2 + head - 1), a(0), a(head - 1)), ((hi2 - tail + 1, hi2), b(tail - 1), b(0))):
            if second[1] > second[0]:
                result.append(Twin((min(one, two), max(one, two)), second, t.reverse))
    return result


def valid_twins(xy: np.ndarray, twins: Sequence[Twin]) -> list[Twin]:
    """The twins whose two ranges really hold the same points (after any re-indexing)."""
    result = []
    for t in twins:
        (lo1, hi1), (lo2, hi2) = t.first, t.second
        if not (0 <= lo1 < hi1 < len(xy) and 0 <= lo2 < hi2 < len(xy)) or hi1 - lo1 != hi2 - lo2 or hi1 > lo2:
            continue
        one, two = xy[lo1:hi1 + 1], xy[lo2:hi2 + 1]
        if np.array_equal(one[::-1] if t.reverse else one, two):
            result.append(t)
    return result


def rolled(twins: Sequence[Twin], shift: int, count: int) -> list[Twin]:
    """The twins after a closed stroke's points were rolled to start at old index `shift`
    (`count` distinct points); twins that would wrap around the new start are dropped."""
    def move(span: tuple[int, int]) -> tuple[int, int] | None:
        lo, hi = (span[0] - shift) % count, (span[1] - shift) % count
        if hi == 0 and span[1] != span[0]:
            hi = count  # the closing point, appended again after the roll
        return (lo, hi) if lo < hi else None

    result = []
    for t in twins:
        first, second = move(t.first), move(t.second)
        if first is not None and second is not None and first[1] <= second[0]:
            result.append(Twin(first, second, t.reverse))
    return result


def mirror_flags(twins: Sequence[Twin], split: np.ndarray, corner: np.ndarray) -> None:
    """In place: split at both ends of both passes, and the same splits and corners inside them."""
    for t in twins:
        for end in (*t.first, *t.second):
            split[end] = True
        for j in range(t.first[0] + 1, t.first[1]):
            m = t.mirror(j)
            split[j] = split[m] = split[j] | split[m]
            corner[j] = corner[m] = corner[j] | corner[m]


def mirror_keep(twins: Sequence[Twin], keep: np.ndarray) -> None:
    """In place: a point is kept for the fit only if it is kept on both passes."""
    for t in twins:
        for j in range(t.first[0] + 1, t.first[1]):
            m = t.mirror(j)
            keep[j] = keep[m] = keep[j] & keep[m]


def twin_piece(twins: Sequence[Twin], lo: int, hi: int) -> tuple[int, int, bool] | None:
    """For a piece (lo, hi) inside a later pass: the earlier pass's piece it repeats, as
    (lo, hi, reverse); None when it repeats nothing."""
    for t in twins:
        if t.second[0] <= lo and hi <= t.second[1]:
            a, b = _unmirror(t, lo), _unmirror(t, hi)
            return (b, a, True) if t.reverse else (a, b, False)
    return None


def _unmirror(t: Twin, m: int) -> int:
    lo1, hi1 = t.first
    offset = m - t.second[0]
    return hi1 - offset if t.reverse else lo1 + offset


def share_pieces(twins: Sequence[Twin], cuts: Sequence[int], pieces: list[np.ndarray]) -> None:
    """In place, after the joints are placed: every piece of a later pass becomes its
    earlier twin's curve again (joint moves and refits may have touched one of them), and
    the pieces just outside the later pass are joined to it."""
    index = {(lo, hi): k for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:]))}
    for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:])):
        source = twin_piece(twins, lo, hi)
        if source is None or (source[0], source[1]) not in index:
            continue
        control = pieces[index[(source[0], source[1])]]
        pieces[k] = np.array(control[::-1, ::-1] if source[2] else control)
        if k > 0 and not np.array_equal(pieces[k - 1][-1, 3], pieces[k][0, 0]):
            before = pieces[k - 1]
            before[-1, 2] += pieces[k][0, 0] - before[-1, 3]
            before[-1, 3] = pieces[k][0, 0]
        if k + 1 < len(pieces) and not np.array_equal(pieces[k + 1][0, 0], pieces[k][-1, 3]):
            after = pieces[k + 1]
            after[0, 1] += pieces[k][-1, 3] - after[0, 0]
            after[0, 0] = pieces[k][-1, 3]
