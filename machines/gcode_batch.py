"""Plain `G0`/`G1 X.. Y.. [F..] [S..]` lines read in bulk, exactly as `GcodeInterpreter` reads them.

The G-code onestroke writes is ~all such lines; reading them one at a time through the
interpreter costs several microseconds each, so job analysis reads runs of them with
numpy instead. Anything else (other words, negative F/S, a modal arc, an undefined
feed, G91, G93, inches, soft limits, laser mode off) is left to the interpreter: a run
stops at the first line the interpreter's own fast path (`GcodeInterpreter._simple`)
would not take, so both give the same floats (same operations in the same order).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from machines.gcode_interpreter import _SIMPLE, GcodeInterpreter

# one match per line: a plain line (the interpreter's own pattern) fills groups 1-5 and
# leaves group 6 empty; any other line (never empty in a Program) lands whole in group 6
_LINES = re.compile(_SIMPLE.pattern + "|^(.+)$", re.MULTILINE)


def split_plain(texts: Sequence[str]) -> list[tuple[str, ...]] | None:
    """(G, X, Y, F, S, other) strings per line ('' where absent; other is the whole line
    unless it is a plain line); None if the texts hold line breaks."""
    rows = _LINES.findall("\n".join(texts))
    return rows if len(rows) == len(texts) else None


@dataclass(frozen=True)
class PlainRun:
    """Moves of `n` consecutive plain lines: start, end (n, 3) mm; feed (n,) mm/min as
    the state holds it after each line; rapid (n,) G0; s (n,) S after each line."""

    n: int
    start: np.ndarray
    end: np.ndarray
    feed: np.ndarray
    rapid: np.ndarray
    s: np.ndarray


def _ffill(values: np.ndarray, first: float) -> np.ndarray:
    """NaN entries take the last non-NaN value before them (`first` before any)."""
    have = ~np.isnan(values)
    last = np.maximum.accumulate(np.where(have, np.arange(len(values)), -1))
    return np.where(last >= 0, values[np.maximum(last, 0)], first)


def _floats(column: Sequence[str]) -> np.ndarray:
    return np.array([v or "nan" for v in column], dtype=float)  # numpy reads each str like float()


def read_plain_run(rows: Sequence[tuple[str, ...]], interp: GcodeInterpreter) -> PlainRun | None:
    """Execute the leading plain lines of `rows` (from `split_plain`) on `interp`'s state.

    Returns the moves of the lines taken (None if none can be: the caller executes
    the next line through the interpreter) and commits the state after the last one.
    """
    st, config = interp.state, interp.config
    if (not rows or not config.laser_mode or config.soft_limits or st.inverse_time or not st.absolute
            or st.inches):
        return None
    g, x, y, f, s = (_floats([r[k] for r in rows]) for k in range(5))
    motion = _ffill(g, float(st.motion))
    feed = _ffill(f, st.feed)  # scale 1.0 (mm): float(F) * 1.0 is float(F)
    negative = np.signbit(f) | np.signbit(s)  # F-0 too: the interpreter leaves any '-' F/S to the general path
    bad = (np.isnan(x) & np.isnan(y)) | negative | ((motion != 0) & (motion != 1)) | ((motion == 1) & (feed == 0))
    stop = np.flatnonzero(bad)
    n = int(stop[0]) if len(stop) else len(rows)
    if n == 0:
        return None
    g, x, y, f, s, motion, feed = (a[:n] for a in (g, x, y, f, s, motion, feed))
    offsets = st.coord_systems[st.coord_index]
    end = np.empty((n + 1, 3))
    end[0] = st.position
    # same operations as the interpreter: float(value) * scale + offset + g92 (scale 1.0)
    end[1:, 0] = _ffill(x * 1.0 + offsets[0] + st.g92[0], st.position[0])
    end[1:, 1] = _ffill(y * 1.0 + offsets[1] + st.g92[1], st.position[1])
    end[1:, 2] = st.position[2]
    s_after = _ffill(s, st.s)
    rapid = motion == 0
    # the state after the last line, as `_simple` leaves it
    given_g = np.flatnonzero(~np.isnan(g))
    if len(given_g):
        st.motion = int(g[given_g[-1]])
    st.feed = float(feed[-1])
    if not np.isnan(s).all():
        st.s = float(s_after[-1])
    st.position = [float(v) for v in end[-1]]
    interp.motion = None
    return PlainRun(n=n, start=end[:-1], end=end[1:], feed=np.where(rapid, np.nan, feed), rapid=rapid,
                    s=s_after)
