"""Tack and lock stitches: a few tiny stitches back and forth over the thread just sewn.

A lock walks back along the needle path from its end by fractions of a lock length and
returns (Ink/Stitch's "half stitch": 0.5, 1, 0.5, 0 of min(path, 1.5 mm)); a tack is the
same figure at the start, sewn forward along the path before the path itself. We make
them ourselves: pyembroidery's `tie_off` emits zero-length stitches and nothing useful.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.graph import arc_lengths

# Positions of the lock's needle points, as fractions of the lock length back from the
# end of the path. Consecutive entries differ, so no lock stitch has zero length.
LOCK_FORMS: dict[str, tuple[float, ...]] = {
    "half": (0.5, 1.0, 0.5, 0.0),
    "back_forth": (1.0, 0.0, 1.0, 0.0),
}


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


def lock_points(path: np.ndarray, options: LockOptions = LockOptions()) -> np.ndarray:
    """Needle points (4, 2) to sew after `path` (N, 2) ends; the last one is its end."""
    length = _lock_length(path, options)
    return walk_back(path, length * np.asarray(LOCK_FORMS[options.form]))


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


def tack_points(path: np.ndarray, options: LockOptions = LockOptions()) -> np.ndarray:
    """Needle points (4, 2) to sew before `path` (N, 2) begins: its start, then the lock
    figure forward along it; the path then continues from its own start. The figure is
    shortened (to half at most) to keep clear of the path's first holes."""
    form = np.asarray(LOCK_FORMS[options.form])
    length = _clear_length(path, _lock_length(path, options), form)
    return np.vstack([path[:1], walk_back(path[::-1], length * form[:-1])])
