"""Seeded synthetic single-line drawings with ground truth, for the vectorizer benchmark.

Every drawing is ONE smooth curve on a 1000 x 1000 px canvas, made of cubic Bézier pieces
(a Hermite spline through waypoints), with its stroke width (2-12 px), a `kind` tag, and
the ground truth the metrics need: the crossing points (the intersections of Table 1), the
touches and near-touches (not intersections; the pen turns back on its own side there), the
out-and-back spikes (retraced, not intersections), and the drawing order (the curve's own
parameterization).

Kinds (`PLAIN_KINDS` have no touches, `TOUCH_KINDS` have at least one):

- open, closed: a wandering line through 5-10 waypoints, crossing itself at whatever angles
  arise (reflex turns make loops);
- loops: cursive loops (a perturbed trochoid), each loop crossing itself;
- shallow: plus 1-2 designed crossings at 5-20 degrees;
- transversal: plus 1-2 designed crossings at 30-90 degrees;
- spike: plus 1-3 straight out-and-back spikes (Y-junctions);
- touch, touch-closed, touch-same: two passes of the line meet tangentially at one point and
  separate again on their own sides (curvatures of opposite sign, exact tangency); in touch
  and touch-closed the passes run in opposite directions (the line comes back alongside
  itself: a wrong turn there still gives one stroke, with a loop run backwards), in
  touch-same in the same direction (a wrong turn splits the line in two);
- near-touch: the same with the centre lines 0.5-0.95 widths apart: the ink merges
  although the line never meets itself;
- triple (`TRIPLE_KINDS`): 1-2 points where three passes cross, their lines at least 35
  degrees apart, and ordinary crossings elsewhere (at least one). The triple point is not
  one of the intersections: its merge zone is a don't-care zone for intersection counting
  (an output's three passes cross in three nearby points there), the order score judges it.

Every sample is checked and regenerated until it is unambiguous for a human while staying
hard: no three passes through one spot (except a triple kind's designed points), no crossing shallower than 5 degrees, no spike whose base
also leads straight to a free end (either branch could be the retraced one), no tight bends
(radius of curvature >= 0.75 width), no place where two passes come within one width of
each other (ink merges) that is not a designed crossing/touch/near-touch, and the ink-merge
zone of every such event at least 3 widths away from any other event and from the ends.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from benchmarks.metrics.drawing_rules import validate
from benchmarks.metrics.ground_truth import CANVAS, MARGIN, Event, GroundTruth, Rejected  # noqa: F401 (re-exported)
from benchmarks.metrics.ink import fair_meta
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

PLAIN_KINDS = ("open", "closed", "loops", "shallow", "transversal", "spike")
TOUCH_KINDS = ("touch", "touch-closed", "touch-same", "near-touch")
TRIPLE_KINDS = ("triple",)
ALL_KINDS = tuple(dict.fromkeys(PLAIN_KINDS + TOUCH_KINDS + TRIPLE_KINDS))
MAX_ATTEMPTS = 600
# realistic single-line drawings cross themselves: fewer crossings than this are redrawn
MIN_CROSSINGS = {"open": 2, "closed": 2, "loops": 2, "spike": 1, "touch": 1, "touch-closed": 1, "touch-same": 1,
                 "near-touch": 1, "triple": 1}


# -- geometry helpers ---------------------------------------------------------------------------

def _rot(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


@dataclass
class _Waypoint:
    pos: np.ndarray
    tangent: np.ndarray | None = None  # fixed unit tangent, or None for Catmull-Rom
    spike: tuple[np.ndarray, float] | None = None  # (unit direction, length) out-and-back here


def _hermite(points: Sequence[_Waypoint], closed: bool, handle: float = 0.36) -> tuple[Stroke, list]:
    """Cubic Bézier spline through waypoints; spikes become straight out-and-back segments.

    Returns the stroke and, per spike, (base, tip, segment index of its first straight piece).
    """
    pos = np.array([w.pos for w in points], dtype=float)
    n = len(pos)
    tan = np.zeros_like(pos)
    for k, w in enumerate(points):
        if w.tangent is not None:
            tan[k] = _unit(np.asarray(w.tangent, dtype=float))
            continue
        if closed:
            prev, nxt = pos[k - 1], pos[(k + 1) % n]
        else:
            prev, nxt = pos[max(k - 1, 0)], pos[min(k + 1, n - 1)]
        tan[k] = _unit(nxt - prev)
    segments = []
    spikes = []
    count = n if closed else n - 1
    for k in range(count):
        k2 = (k + 1) % n
        p0, p3 = pos[k], pos[k2]
        chord = np.linalg.norm(p3 - p0)
        segments.append([p0, p0 + tan[k] * chord * handle, p3 - tan[k2] * chord * handle, p3])
        w = points[k2]
        if w.spike is not None and (closed or k2 != n - 1):
            direction, length = w.spike
            tip = p3 + direction * length
            spikes.append((p3.copy(), tip, len(segments)))
            segments.append([p3, p3 + (tip - p3) / 3, p3 + 2 * (tip - p3) / 3, tip])
            segments.append([tip, tip + (p3 - tip) / 3, tip + 2 * (p3 - tip) / 3, p3])
    return Stroke(np.array(segments)), spikes


def _wander(rng: np.random.Generator, start: np.ndarray, heading: float, n: int, step: float,
            box: float, turn: float) -> list[_Waypoint]:
    """n waypoints of a random walk with smooth heading changes, kept inside [0, box]^2."""
    out = []
    p = np.array(start, dtype=float)
    centre = np.array([box / 2, box / 2])
    for _ in range(n):
        heading += rng.normal(0.0, turn)
        to_centre = centre - p
        if np.linalg.norm(to_centre) > 0.38 * box:
            want = np.arctan2(to_centre[1], to_centre[0])
            diff = (want - heading + np.pi) % (2 * np.pi) - np.pi
            heading += 0.6 * diff
        p = p + step * rng.uniform(0.7, 1.3) * np.array([np.cos(heading), np.sin(heading)])
        p = np.clip(p, 0.0, box)
        out.append(_Waypoint(p.copy()))
    return out


def _random_points(rng: np.random.Generator, n: int, box: float, avoid: Sequence[np.ndarray] = (),
                   min_dist: float = 0.0) -> list[_Waypoint]:
    out = []
    for _ in range(n):
        for _try in range(50):
            p = rng.uniform(0.05 * box, 0.95 * box, size=2)
            if all(np.linalg.norm(p - q) >= min_dist for q in avoid):
                break
        out.append(_Waypoint(p))
    return out


# -- designed features --------------------------------------------------------------------------

def _meeting(rng: np.random.Generator, box: float, kind: str, width: float, opposite: bool | None = None):
    """Waypoints around one designed meeting of two passes.

    Returns (first_pass, loop, second_pass, event_point, angle): first_pass and
    second_pass are 3 waypoints each (before, at, after the meeting), loop the waypoints the
    line visits between the passes.
    """
    x = rng.uniform(0.3 * box, 0.7 * box, size=2)
    u1 = _rot(np.array([1.0, 0.0]), rng.uniform(0, 2 * np.pi))
    normal = _rot(u1, np.pi / 2)
    a = rng.uniform(0.12, 0.2) * box
    b = rng.uniform(0.12, 0.2) * box
    reverse = rng.random() < 0.5 if opposite is None else opposite
    if kind in ("shallow", "transversal"):
        lo, hi = (5.0, 20.0) if kind == "shallow" else (30.0, 90.0)
        angle = rng.uniform(lo, hi)
        u2 = _rot(u1, np.radians(angle) * rng.choice([-1, 1]))
        if reverse:
            u2 = -u2
        p1 = [_Waypoint(x - a * u1, u1), _Waypoint(x.copy(), u1), _Waypoint(x + a * u1, u1)]
        p2 = [_Waypoint(x - b * u2, u2), _Waypoint(x.copy(), u2), _Waypoint(x + b * u2, u2)]
        event = x.copy()
    else:  # touch / near-touch: two arcs bending away from each other
        angle = 0.0
        u2 = -u1 if reverse else u1.copy()
        phi1 = np.radians(rng.uniform(12, 30))
        phi2 = np.radians(rng.uniform(12, 30))
        gap = 0.0 if kind == "touch" else rng.uniform(0.5, 0.95) * width
        x2 = x - gap * normal

        def arc(centre, u, side, chord, phi):
            # points at chord distance, angle phi off the tangent toward `side`; tangents of a circle
            before = centre + chord * (-np.cos(phi) * u + np.sin(phi) * side)
            after = centre + chord * (np.cos(phi) * u + np.sin(phi) * side)
            left = u[0] * side[1] - u[1] * side[0] > 0  # side is to the left of u
            t_before = _rot(u, -2 * phi) if left else _rot(u, 2 * phi)
            t_after = _rot(u, 2 * phi) if left else _rot(u, -2 * phi)
            return [_Waypoint(before, t_before), _Waypoint(centre.copy(), u), _Waypoint(after, t_after)]

        p1 = arc(x, u1, normal, a, phi1)
        p2 = arc(x2, u2, -normal, b, phi2)
        event = x - gap / 2 * normal
    # the loop between the passes: from after pass 1 to before pass 2, away from the meeting
    far = rng.integers(1, 3)
    loop = _random_points(rng, int(far), box, avoid=[x], min_dist=0.3 * box)
    return p1, loop, p2, event, angle


def _triple(rng: np.random.Generator, box: float) -> tuple[list[_Waypoint], np.ndarray, float]:
    """Waypoints of three passes through one point, their lines 35-110 degrees apart, with
    1-2 far waypoints between the passes; returns (waypoints, point, smallest angle)."""
    x = rng.uniform(0.3 * box, 0.7 * box, size=2)
    g1 = rng.uniform(35.0, 75.0)
    g2 = rng.uniform(35.0, min(75.0, 145.0 - g1))  # the third gap, 180 - g1 - g2, is >= 35 too
    lines = np.radians(rng.uniform(0, 180) + np.array([0.0, g1, g1 + g2]))
    seq: list[_Waypoint] = []
    for k in rng.permutation(3):
        u = np.array([np.cos(lines[k]), np.sin(lines[k])]) * rng.choice([-1, 1])
        a = rng.uniform(0.1, 0.18) * box
        if seq:
            seq += _random_points(rng, int(rng.integers(1, 3)), box, avoid=[x], min_dist=0.3 * box)
        seq += [_Waypoint(x - a * u, u), _Waypoint(x.copy(), u), _Waypoint(x + a * u, u)]
    return seq, x, float(min(g1, g2, 180.0 - g1 - g2))


def _trochoid(rng: np.random.Generator, box: float) -> list[_Waypoint]:
    loops = int(rng.integers(2, 6))
    c = 1.0
    r = rng.uniform(1.7, 3.2)
    step = np.pi / 3
    t = np.arange(-np.pi / 2, 2 * np.pi * loops + np.pi / 2 + 1e-9, step)
    amp = r * (1 + 0.15 * np.sin(rng.uniform(0, 2 * np.pi) + 0.7 * t))
    xs = c * t - amp * np.sin(t)
    ys = -amp * np.cos(t) * rng.uniform(0.8, 1.3)
    dx = c - amp * np.cos(t)
    dy = amp * np.sin(t)
    pts = np.c_[xs, ys] + rng.normal(0, 0.06 * r, size=(len(t), 2))
    tans = _unit(np.c_[dx, dy])
    theta = rng.uniform(-0.5, 0.5) + (np.pi if rng.random() < 0.5 else 0.0)
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    pts = pts @ rot.T
    tans = tans @ rot.T
    # a gentle bend of the whole row
    span = pts[:, 0].max() - pts[:, 0].min()
    pts[:, 1] += rng.uniform(-0.15, 0.15) * span * np.sin(np.pi * (pts[:, 0] - pts[:, 0].min()) / span)
    ext = np.ptp(pts, axis=0).max()
    pts = (pts - pts.min(axis=0)) / ext * box
    return [_Waypoint(p, tg) for p, tg in zip(pts, tans)]


def _build(kind: str, rng: np.random.Generator, width: float, box: float) -> tuple[list[_Waypoint], bool, list]:
    """Waypoints, closedness and the designed events (kind, point, angle) of one sample."""
    closed = kind in ("closed", "touch-closed") or (kind in ("shallow", "transversal", "spike", "triple")
                                                      and rng.random() < 0.35)
    designed = []
    if kind == "loops":
        return _trochoid(rng, box), False, designed
    if kind in ("open", "closed", "spike"):
        n = int(rng.integers(8, 14))
        start = rng.uniform(0.2 * box, 0.8 * box, size=2)
        pts = _wander(rng, start, rng.uniform(0, 2 * np.pi), n, 0.28 * box, box, rng.uniform(1.0, 2.2))
        if kind == "spike":
            nspikes = int(rng.integers(1, 4))
            candidates = rng.permutation(np.arange(1, n - 1))[:nspikes]
            for k in candidates:
                along = _unit(pts[k + 1].pos - pts[k - 1].pos)  # the spline's tangent there
                direction = _rot(along, np.radians(rng.uniform(40, 140)) * rng.choice([-1, 1]))
                length = rng.uniform(max(5 * width, 30.0), max(9 * width, 0.2 * box))
                pts[k].spike = (direction, length)
        return pts, closed, designed
    if kind == "triple":
        seq = [] if closed else _random_points(rng, 1, box)
        for k in range(int(rng.integers(1, 3))):
            if k:
                seq += _random_points(rng, 1, box)
            points, x, angle = _triple(rng, box)
            seq += points
            designed.append(("triple", x, angle))
        seq += [] if closed else _random_points(rng, 1, box)
        return seq, closed, designed
    meeting_kind = {"shallow": "shallow", "transversal": "transversal", "touch": "touch",
                    "touch-closed": "touch", "touch-same": "touch", "near-touch": "near-touch"}[kind]
    # touch, touch-closed, near-touch: the line comes back alongside itself (passes in
    # opposite directions), so the crossing pairing still gives ONE stroke with a loop run
    # backwards; only the image tells the two apart. touch-same: passes in the same
    # direction, where the crossing pairing splits the line in two and a retry recovers.
    opposite = None if meeting_kind not in ("touch", "near-touch") else kind != "touch-same"
    count = int(rng.integers(1, 3)) if kind in ("shallow", "transversal") else 1
    seq: list[_Waypoint] = []
    if not closed:
        seq += _random_points(rng, int(rng.integers(1, 3)), box)
    for _ in range(count):
        p1, loop, p2, event, angle = _meeting(rng, box, meeting_kind, width, opposite)
        seq += p1 + loop + p2
        designed.append((meeting_kind, event, angle))
        if count > 1:
            seq += _random_points(rng, 1, box)
    if not closed:
        seq += _random_points(rng, int(rng.integers(1, 3)), box)
    else:
        seq += _random_points(rng, int(rng.integers(1, 3)), box, avoid=[d[1] for d in designed],
                              min_dist=0.25 * box)
    return seq, closed, designed


# -- public API ---------------------------------------------------------------------------------

def drawing_width(index: int, seed: int) -> float:
    """Stroke width of drawing `index`: spread evenly over 2-12 px (golden-ratio sequence)."""
    frac = (index * 0.6180339887498949 + seed * 0.3819660112501051 + 0.1) % 1.0
    return float(np.round((2.0 + 10.0 * frac) * 4) / 4)


FLATTEN_TOLERANCE = 0.05  # px: the pen path the fair-retrace facts are read from (a spike's straight
# out-and-back segments flatten to the same two points both ways, so the merged graph sees one edge)


def generate_drawing(kind: str, seed: int = 0, index: int = 0) -> GroundTruth:
    """One validated drawing of `kind`, determined by (seed, index, kind)."""
    if kind not in ALL_KINDS:
        raise ValueError(f"unknown drawing kind {kind!r}; use one of {ALL_KINDS}")
    width = drawing_width(index, seed)
    kind_id = ALL_KINDS.index(kind)
    last = "no attempt"
    for attempt in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([seed, index, kind_id, attempt])
        box = rng.uniform(450, CANVAS - 2 * MARGIN - 2 * width)
        waypoints, closed, designed = _build(kind, rng, width, box)
        stroke, spikes = _hermite(waypoints, closed)
        # place the drawing at a random spot of the canvas
        xmin, ymin, xmax, ymax = stroke.bounds()
        room = CANVAS - 2 * (MARGIN + width + 1)
        if xmax - xmin > room or ymax - ymin > room:
            last = "too big"
            continue
        offset = np.array([rng.uniform(MARGIN + width + 1 - xmin, CANVAS - MARGIN - width - 1 - xmax),
                           rng.uniform(MARGIN + width + 1 - ymin, CANVAS - MARGIN - width - 1 - ymax)])
        stroke = stroke.transformed(np.array([[1, 0, offset[0]], [0, 1, offset[1]]]))
        designed = [(k, np.asarray(e) + offset, a) for k, e, a in designed]
        spikes = [(b + offset, t + offset, seg) for b, t, seg in spikes]
        if closed:
            stroke = _close_exactly(stroke)
        try:
            events, crossings, dont_care = validate(stroke, closed, width, designed, spikes)
            if len(crossings) < MIN_CROSSINGS.get(kind, 0):
                raise Rejected("too few crossings")
        except Rejected as why:
            last = str(why)
            continue
        drawing = Drawing((stroke,), CANVAS, CANVAS, unit="px", stroke_width=width)
        return GroundTruth(name=f"{kind}-{seed}-{index}", kind=kind, drawing=drawing, closed=closed,
                           intersections=np.asarray(crossings).reshape(-1, 2), events=tuple(events),
                           dont_care=tuple(dont_care),
                           meta={"seed": seed, "index": index, "attempts": attempt + 1, "width": width,
                                 **fair_meta(stroke.flatten(FLATTEN_TOLERANCE))})
    raise RuntimeError(f"no valid {kind} drawing after {MAX_ATTEMPTS} attempts (last: {last})")


def _close_exactly(stroke: Stroke) -> Stroke:
    c = np.array(stroke.control)
    c[-1, 3] = c[0, 0]
    return Stroke(c)


def generate_set(name: str, count: int, seed: int = 0) -> list[GroundTruth]:
    """`count` drawings of set "plain" (PLAIN_KINDS in turn) or "touch" (TOUCH_KINDS in turn)."""
    kinds = {"plain": PLAIN_KINDS, "touch": TOUCH_KINDS, "triple": TRIPLE_KINDS}.get(name)
    if kinds is None:
        raise ValueError(f"unknown generated set {name!r}; use 'plain', 'touch' or 'triple'")
    offset = {"plain": 0, "touch": 10_000, "triple": 20_000}[name]
    return [generate_drawing(kinds[i % len(kinds)], seed, offset + i) for i in range(count)]
