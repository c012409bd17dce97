"""Tack and lock stitches: a few tiny stitches back and forth over the thread just sewn.

A lock walks back along the needle path from its end by fractions of a lock length and
returns (Ink/Stitch's "half stitch": 0.5, 1, 0.5, 0 of min(path, 1.5 mm)); a tack is the
same figure at the start, sewn forward along the path before the path itself. We make
them ourselves: pyembroidery's `tie_off` emits zero-length stitches and nothing useful.

Where a tack or lock would crowd the needle points around it (a short stroke, a tight
start), the planner asks for a lighter one: `level` 1 sews a single stitch there and
back (`SINGLE`), level 2 (`TIE_LEVELS` - 1) none at all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from fabrication.embroidery.needles import STITCH
from fabrication.embroidery.quality import DENSITY_LIMIT, DENSITY_RADIUS
from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.stroke import arc_lengths

# Positions of the lock's needle points, as fractions of the lock length back from the
# end of the path. Consecutive entries differ, so no lock stitch has zero length.
LOCK_FORMS: dict[str, tuple[float, ...]] = {
    "half": (0.5, 1.0, 0.5, 0.0),
    "back_forth": (1.0, 0.0, 1.0, 0.0),
}
# The lighter figure of level 1: one stitch back (forward for a tack) and return.
SINGLE = (1.0, 0.0)
TIE_LEVELS = 3  # 0: the chosen form, 1: SINGLE, 2: none


@dataclass(frozen=True, kw_only=True)
class LighterTie:
    """A tack (lock=False) or lock made lighter for density: where it starts (tack) or
    ends (lock), x, y in mm; level 1: a single stitch there and back, 2: left out."""

    x: float
    y: float
    lock: bool
    level: int


LOCK_LENGTH = Range(0.0, None, unit="mm", name="lock length", low_open=True)

@dataclass(frozen=True, kw_only=True)
class LockOptions:
    """form: a key of LOCK_FORMS; length: how far back along the path a lock reaches, mm."""

    form: str = "half"
    length: float = ranged(1.5, LOCK_LENGTH)

    def __post_init__(self) -> None:
        check_ranges(self)
        if self.form not in LOCK_FORMS:
            raise InputError(f"unknown lock form {self.form!r}; use one of {', '.join(LOCK_FORMS)}")


def walk_back(path: np.ndarray, distances: np.ndarray) -> np.ndarray:
    """Points at arc `distances` (m,) mm back from the last point of polyline `path` (N, 2)."""
    rev = path[::-1]
    cum = arc_lengths(rev)
    d = np.clip(distances, 0.0, cum[-1])
    return np.column_stack([np.interp(d, cum, rev[:, 0]), np.interp(d, cum, rev[:, 1])])


def _lock_length(path: np.ndarray, options: LockOptions) -> float:
    total = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
    return min(options.length, total)


def _form(options: LockOptions, level: int) -> np.ndarray:
    if not 0 <= level < TIE_LEVELS:
        raise ValueError(f"tie level {level} is not in [0, {TIE_LEVELS})")
    return np.asarray(LOCK_FORMS[options.form] if level == 0 else SINGLE if level == 1 else ())


def lock_points(path: np.ndarray, options: LockOptions = LockOptions(), level: int = 0) -> np.ndarray:
    """Needle points (4, 2) to sew after `path` (N, 2) ends, the last one its end; (2, 2)
    at `level` 1, (0, 2) at level 2."""
    length = _lock_length(path, options)
    return walk_back(path, length * _form(options, level))


# A tack's holes keep this far (mm, along the path) from the holes the stitches after it
# make, so the needle never pierces right beside a hole it made a moment before (0.2 mm
# plus the files' 0.1 mm grid).
TACK_CLEARANCE = 0.35


def _clear_length(path: np.ndarray, length: float, form: np.ndarray) -> float:
    """The tack length in [length / 2, length] whose holes (at `form` x length along
    `path`) lie furthest from the path's own holes, preferring the longest that keeps
    TACK_CLEARANCE."""
    cum = arc_lengths(path)[1:]
    if not len(cum):
        return length
    marks = np.unique(form[form > 0])
    candidates = length * np.linspace(1.0, 0.5, 11)
    # the hole nearest any mark lies at most one past the furthest mark: later holes never count
    cum = cum[:np.searchsorted(cum, length * marks.max(), side="right") + 1]
    # all candidates at once (a design of 20,000 strokes has 20,000 tacks)
    gaps = np.abs((candidates[:, None] * marks)[:, :, None] - cum[None, None, :]).min(axis=(1, 2))
    clear = np.flatnonzero(gaps >= TACK_CLEARANCE)
    if len(clear):
        return float(candidates[clear[0]])
    return float(candidates[int(np.argmax(gaps))])  # the first of the widest gaps, as before


def tack_points(path: np.ndarray, options: LockOptions = LockOptions(), level: int = 0) -> np.ndarray:
    """Needle points (4, 2) to sew before `path` (N, 2) begins: its start, then the lock
    figure forward along it; the path then continues from its own start. The figure is
    shortened (to half at most) to keep clear of the path's first holes. (2, 2) at
    `level` 1, (0, 2) at level 2."""
    form = _form(options, level)
    if not len(form):
        return np.zeros((0, 2))
    length = _clear_length(path, _lock_length(path, options), form)
    return np.vstack([path[:1], walk_back(path[::-1], length * form[:-1])])


def crowding_ties(points: np.ndarray, kinds: np.ndarray, ties: np.ndarray,
                   levels: dict[int, int]) -> set[int]:
    """The ties (tacks and locks, by number) to make lighter, each one level: `points`
    (N, 2) mm and `kinds` (N,) of a plan's rows, `ties` (N,) the tie of each row (2 c: the
    tack of chain c, 2 c + 1: its lock, -1: none), `levels` the ties' levels so far. They are the ties that make a place too dense: needle points
    within the density radius of a needle point with more than the density limit around it
    (every needle point counted) that would be within the limit without the ties' points,
    or that is a tie's own point. Where the stitches alone are too dense, the ties stay (the
    warning names the place)."""
    needle = kinds == STITCH
    pts, tie = points[needle], ties[needle]
    at_tie = tie >= 0
    if not at_tie.any():
        return set()
    reach = DENSITY_RADIUS + 1e-9
    # Only places near a tie can be helped by a lighter tie: count there, not everywhere.
    tree = cKDTree(pts, balanced_tree=False, compact_nodes=False)  # 3x quicker to build
    near = np.zeros(len(pts), dtype=bool)
    for found in tree.query_ball_point(pts[at_tie], reach):
        near[found] = True
    crowding: set[int] = set()
    centres = np.flatnonzero(near)
    for centre, found in zip(centres.tolist(), tree.query_ball_point(pts[centres], reach)):
        ours = tie[found]
        # A place centred on a tie's own needle point goes with the tie.
        if len(found) > DENSITY_LIMIT and (tie[centre] >= 0 or len(found) - int((ours >= 0).sum()) <= DENSITY_LIMIT):
            ours = set(ours[ours >= 0].tolist())
            tacks = {t for t in ours if t % 2 == 0 and levels.get(t, 0) < TIE_LEVELS - 1}
            # A lock holds the thread against the trim after it: tacks give way first.
            crowding |= tacks or {t for t in ours if levels.get(t, 0) < TIE_LEVELS - 1}
    return crowding
