"""Where the pen turned, read from the ink: a narrow cusp's tip beyond its corner, and a cusp's
tip beyond a fork or a turn of the traced line whose spur pruning took (`fitting.fit_stroke`
asks at its corners, turns and splits)."""

from __future__ import annotations

import numpy as np

from vectorize.fit.ink_guard import STEP, InkGuard
from vectorize.fit.retraces import Twin
from vectorize.fit.traced import point_records
from vectorize.stroke import arc_lengths


def tip_in_ink(xy: np.ndarray, arc: np.ndarray, at: int, guard: InkGuard, stroke_width: float,
                closed: bool, turn: float = 0.0, within: float = 3.0) -> np.ndarray | None:
    """Where the pen turned at the corner `xy[at]` of the traced centre line ((N, 2) px;
    `arc` (N,) px: arc length at each point), read from the ink: along the corner's outward
    bisector (away from both sides, as seen 1.5 widths along the line), half a width short of
    where the ink ends (the pen's round tip). None when the ink does not end within `within` widths.

    At a narrow cusp (the top of a handwritten i, n or u) both sides merge into one blob of
    ink before the tip: the medial axis turns back a width or more short of it, and the two
    sides' tangents, bent by that turn, meet short of the tip too; the ink still shows how
    far the pen went. At an ordinary sharp corner the ink's round outer edge lies half a
    width beyond the corner, so this finds the corner itself. `turn`: degrees to turn the
    bisector by before looking along it.
    """
    reach = 1.5 * stroke_width
    sides = []
    for target in (arc[at] - reach, arc[at] + reach):
        if closed:
            target = np.mod(target, arc[-1])
        elif not 0.0 <= target <= arc[-1]:
            return None
        # np.interp on the few points around the target: the same value as over the whole
        # line, without copying the line at every corner (TSP art has thousands)
        j = int(np.searchsorted(arc, target, side="right"))
        near = slice(max(j - 2, 0), min(j + 2, len(arc)))
        point = np.array([np.interp(target, arc[near], xy[near, 0]), np.interp(target, arc[near], xy[near, 1])])
        chord = point - xy[at]
        if np.linalg.norm(chord) < 1e-9:
            return None
        sides.append(chord / np.linalg.norm(chord))
    inward = sides[0] + sides[1]
    if np.linalg.norm(inward) < 1e-6:
        return None  # the line runs straight through: no corner to extend
    direction = -inward / np.linalg.norm(inward)
    if turn:
        c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))
        direction = np.array([c * direction[0] - s * direction[1], s * direction[0] + c * direction[1]])
    count = int(np.ceil(within * stroke_width / (STEP / 2)))
    steps = np.arange(1, count + 1) * (within * stroke_width / count)
    outside = guard.excess(xy[at] + steps[:, None] * direction) > 0.0
    if not outside.any():
        return None
    # The first step found outside lies up to the guard's margin beyond the ink's edge.
    edge = float(steps[int(np.argmax(outside))]) - guard.margin
    return xy[at] + max(edge - 0.5 * stroke_width, 0.0) * direction


# A turn at a fork (`_trace` splits there: a node of three or more branches) looks for the
# pen's tip beyond it within FORK_FAN degrees either side of the turn's bisector, in steps of
# FORK_STEP: near a fork the sides' axes bend towards the third branch (at
# he_hummed_the_name-0-36's m's the way in's axis heads 27 degrees off its line over the last
# 8 px), so the bisector misses the tip.
FORK_FAN, FORK_STEP = 45.0, 5.0
# Widths from the fork within which the tip's ink must end: the m's tips lie 2.5-3 widths
# beyond their forks, their ink ending half a width further.
FORK_REACH = 5.0
# Widths the tip must lie beyond every medial ball (ink no branch holds): the ink the balls
# leave between them at the 14 forks of he_hummed_the_name-0-36 reaches 0.15 w beyond them;
# the m's pruned tips lie 0.59 and 1.02 w beyond.
FORK_TIP_BEYOND = 0.3
# Only where the pen reverses its heading at the fork: the two sides, FORK_V_SIDES widths
# along the line, open at most FORK_V_MAX degrees. The m's cusps above (and the test's) open
# 27-37 degrees; the four other forks of the cursive set (seed 0) with ink beyond the balls
# open 131 and 159 (two m's whose traced line does not turn back at that fork), 153 (inside an h's band
# of three strands, next to a pinhole) and 0.3 (a turn back over one stem, the tip 8 px up
# its band): a tip there would be drawn where the pen did not turn.
FORK_V_SIDES, FORK_V_MAX = 4.0, 60.0


def _fork_tip(xy: np.ndarray, arc: np.ndarray, at: int, guard: InkGuard, stroke_width: float,
              closed: bool) -> np.ndarray | None:
    """Where the pen turned at the fork `xy[at]`, when the ink shows a tip beyond it that no
    branch's medial ball holds: the farthest within `FORK_FAN` degrees of the bisector, or None.

    A cusp whose spur pruning took leaves a tip the fit finds at a corner (`tip_in_ink`), but
    where a third branch leaves within the cusp's merged ink (a cursive m's entry cusp above
    the fork of its first arch) the turn is at the fork and no corner is looked for; the curve
    turned 10 px short of the cusp. Beyond a fork most ink is another branch's (a connecting
    stroke turning up a stem that goes on down): only ink beyond every ball is the tip's.
    """
    tips = [tip for turn in np.arange(-FORK_FAN, FORK_FAN + 0.5 * FORK_STEP, FORK_STEP)
            if (tip := tip_in_ink(xy, arc, at, guard, stroke_width, closed, float(turn), FORK_REACH)) is not None
            and guard.beyond_balls(tip)[0] > FORK_TIP_BEYOND * stroke_width]
    return max(tips, key=lambda tip: float(np.linalg.norm(tip - xy[at])), default=None)


def _reverses(xy: np.ndarray, arc: np.ndarray, i: int, stroke_width: float, closed: bool) -> bool:
    """Whether the pen reverses its heading at `xy[i]` (a V): the two sides, `FORK_V_SIDES`
    widths along the line, open at most `FORK_V_MAX` degrees and end more than a width apart
    (not a turn back over one branch, both sides the same points, nor a bend into another stroke)."""
    reach = FORK_V_SIDES * stroke_width
    if closed or arc[i] < reach or arc[i] + reach > arc[-1]:
        return False
    ends = np.array([[np.interp(arc[i] + d, arc, xy[:, k]) for k in (0, 1)] for d in (-reach, reach)])
    sides = ends - xy[i]
    norms = float(np.linalg.norm(sides[0]) * np.linalg.norm(sides[1]))
    cos = float(np.dot(sides[0], sides[1])) / max(norms, 1e-9)
    return cos > np.cos(np.radians(FORK_V_MAX)) and float(np.linalg.norm(ends[1] - ends[0])) > stroke_width


def corner_tip(xy: np.ndarray, arc: np.ndarray, at: int, guard: InkGuard, stroke_width: float,
               closed: bool) -> np.ndarray | None:
    """Where the pen turned at the corner `xy[at]` (not a fork): the ink's tip along the
    bisector (`tip_in_ink`) or, where the pen reverses its heading, the tip of ink no medial
    ball holds (`_fork_tip`), whichever lies farther; None when neither is found.

    A cusp whose sides merge for a long way (a u's entry cusp 14 degrees wide with a hook at
    its tip: the_little_duck_had_tea-4-9) loses its spur to pruning 2-3 widths below its tip;
    the ink runs on beyond `tip_in_ink`'s 3 widths (7.5 px at a 2.3 px line), or the tip lies
    off the bisector where the pen hooked into the turn. Ink beyond every ball is the pruned
    spur's own, so it is looked for out to `FORK_REACH` widths and `FORK_FAN` degrees either side.
    """
    tip = tip_in_ink(xy, arc, at, guard, stroke_width, closed)
    if not _reverses(xy, arc, at, stroke_width, closed):
        return tip
    spur = _fork_tip(xy, arc, at, guard, stroke_width, closed)
    if spur is None or (tip is not None and np.linalg.norm(tip - xy[at]) >= np.linalg.norm(spur - xy[at])):
        return tip
    return spur


# A turn of the traced line that `fitting.sharp_corners` does not call a corner, because the axis
# rounds it off where a cusp's spur was pruned (i_like_mint_tea_at_midday-4-14's m entry: 111
# degrees over 1.5 widths, 65 of them within half a width, 0.6 needed), is a corner when the pen
# reverses there and the ink shows a tip no medial ball holds: it turns more than TURN_MIN
# degrees over 1.5 widths either side, the least any corner turns.
TURN_MIN = 40.0


def pruned_cusps(xy: np.ndarray, arc: np.ndarray, wide: np.ndarray, free: np.ndarray, guard: InkGuard,
                 stroke_width: float, closed: bool) -> np.ndarray:
    """Indices of the turns of the traced line ((N, 2) px; `arc` (N,) px: arc length at each
    point) where a cusp's spur was pruned: the sharpest point of each run of turns over
    `TURN_MIN` degrees (`wide`: (N,) rad over 1.5 widths either side), where `free` ((N,) bool)
    allows a corner, the pen reverses its heading (`_reverses`) and `_fork_tip` finds ink
    beyond every ball (the spur's)."""
    found = []
    turning = wide > np.radians(TURN_MIN)
    # runs of turning points: one candidate each, its sharpest
    edges = np.flatnonzero(np.diff(np.r_[0, turning.astype(np.int8), 0]))
    for lo, hi in zip(edges[::2], edges[1::2]):
        i = lo + int(np.argmax(wide[lo:hi]))
        if not free[lo:hi].all() or not _reverses(xy, arc, i, stroke_width, closed):
            continue
        if _fork_tip(xy, arc, i, guard, stroke_width, closed) is not None:
            found.append(i)
    return np.array(found, dtype=int)


def with_fork_tips(points: np.ndarray, twins: list[Twin], guard: InkGuard, stroke_width: float,
                   closed: bool) -> tuple[np.ndarray, list[Twin]]:
    """The traced points ((N,) `traced.POINT` records, as `fitting.fit_stroke` holds them)
    with a spike out to each fork's tip (`_fork_tip`) and back: the points [tip, fork]
    inserted after the fork where the pen turns (a split there, or a corner), split at both
    (the spike is fitted straight and retraced, as the route retraces a spike). Returns the
    (N',) records and the twins moved along."""
    xy = points["xy"]
    arc = arc_lengths(xy)

    turns = [int(i) for i in np.flatnonzero(points["split"] & points["junction"])
             if 0 < i < len(xy) - 1 and _reverses(xy, arc, int(i), stroke_width, closed)]
    tips = {i: tip for i in turns if (tip := _fork_tip(xy, arc, i, guard, stroke_width, closed)) is not None}
    if tips:
        points = points.copy()
    for i in sorted(tips, reverse=True):
        points["corner"][i] = False  # the pen turns at the tip; the fork is where the spike leaves
        spike = point_records([tips[i], points["xy"][i]], keep=True, split=True)
        points = np.insert(points, i + 1, spike)
        # Ranges after the fork move on by the two points (one across it no longer matches
        # its partner and is dropped by `valid_twins`).
        def moved(span: tuple[int, int], i: int = i) -> tuple[int, int]:
            lo, hi = span
            return (lo + 2 if lo >= i and hi > i else lo, hi + 2 if hi > i else hi)

        twins = [Twin(moved(t.first), moved(t.second), t.reverse) for t in twins]
    return points, twins
