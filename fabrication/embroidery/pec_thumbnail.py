"""The PEC thumbnail of a .pes file, drawn with numpy instead of pyembroidery's per-point loop.

Every .pes file ends with 48x38 one-bit icons of the design. pyembroidery 1.5 draws them
with `PecGraphics.draw_scaled`, which marks one pixel per stitch through a Python
`try/except AttributeError` per point: for 100,000 stitches that is ~0.4 s, 40 % of the
whole .pes write. `numpy_draw_scaled` computes the same pixels from the same float
arithmetic in a few vectorised steps (the bytes are identical; tests compare them against
pyembroidery's own function), and `fast_pec_thumbnails()` swaps it in for the duration of
one write. Everything else in the file is still pyembroidery's.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from math import floor

import numpy as np
from pyembroidery import PecWriter

# None if a later pyembroidery no longer has this function: then nothing is swapped.
_original_draw_scaled = getattr(PecWriter, "draw_scaled", None)
_swap_lock = threading.Lock()


def _extents(extends) -> tuple[float, float, float, float]:
    try:
        return extends.left, extends.top, extends.right, extends.bottom
    except AttributeError:
        return extends[0], extends[1], extends[2], extends[3]


def numpy_draw_scaled(extends, points, graphic: list, stride: int, buffer: int = 5) -> None:
    """Mark `points` (rows [x, y, ...] in 0.1 mm) scaled into the icon `graphic` (a list of
    byte values, `stride` bytes per row) exactly as `PecGraphics.draw_scaled` does,
    including its quirks: negative indices wrap, indices past the end are skipped."""
    if extends is None or not isinstance(points, list):
        _original_draw_scaled(extends, points, graphic, stride, buffer)
        return
    if not points:
        return
    try:  # pyembroidery's stitches are [x, y, command] lists
        xy = np.array(points, dtype=np.float64)[:, :2]
    except (TypeError, ValueError, IndexError):  # anything else: the library's own loop
        _original_draw_scaled(extends, points, graphic, stride, buffer)
        return
    # The scalars below repeat the library's Python float arithmetic step by step, so that
    # every floor() lands on the same side.
    left, top, right, bottom = _extents(extends)
    diagram_width = right - left or 1
    diagram_height = bottom - top or 1
    graphic_width = stride * 8
    graphic_height = len(graphic) / stride
    scale = min((graphic_width - buffer) / float(diagram_width),
                (graphic_height - buffer) / float(diagram_height))
    translate_x = -((right + left) / 2) * scale + graphic_width / 2
    translate_y = -((bottom + top) / 2) * scale + graphic_height / 2
    px = np.floor(xy[:, 0] * scale + translate_x).astype(np.int64)
    py = np.floor(xy[:, 1] * scale + translate_y).astype(np.int64)
    # graphic[(y * stride) + int(x / 8)] |= 1 << (x % 8), with Python's int() and %.
    index = py * stride + np.trunc(px / 8).astype(np.int64)
    bit = np.left_shift(1, np.mod(px, 8))
    size = len(graphic)
    inside = (index >= -size) & (index < size)
    index = np.mod(index[inside], size)
    marks = np.zeros(size, dtype=np.int64)
    np.bitwise_or.at(marks, index, bit[inside])
    for i in np.flatnonzero(marks).tolist():
        graphic[i] |= int(marks[i])


@contextlib.contextmanager
def fast_pec_thumbnails() -> Iterator[None]:
    """Within the block, pyembroidery's PEC writer draws thumbnails with `numpy_draw_scaled`."""
    if _original_draw_scaled is None:
        yield
        return
    with _swap_lock:
        PecWriter.draw_scaled = numpy_draw_scaled
        try:
            yield
        finally:
            PecWriter.draw_scaled = _original_draw_scaled


__all__ = ["numpy_draw_scaled", "fast_pec_thumbnails"]
