"""Read any embroidery file pyembroidery knows into a `StitchPlan` (for previews and tests)."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import pyembroidery

from fabrication.embroidery.needles import BODY
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, StitchPlan
from fabrication.embroidery.thread import Thread
from onestroke.errors import InputError
from onestroke.paths import check_input_file

# pyembroidery commands that end a run of thread like a trim does.
_CUTS = (pyembroidery.TRIM, pyembroidery.COLOR_CHANGE, pyembroidery.NEEDLE_SET, pyembroidery.STOP)


@dataclass(frozen=True, eq=False)
class EmbroideryFile:
    """A file read back: `plan` (rows as STITCH/JUMP/TRIM, params = progress 0..1),
    `threads` (RGB per colour block), `color_changes` and `blocks` (N,) int: the colour
    block of each row of `plan` (0, 1, ...; a colour change row opens the next block; may
    exceed len(threads) - 1 when a file, like DST, has more blocks than threads)."""

    plan: StitchPlan
    threads: tuple[tuple[int, int, int], ...]
    color_changes: int
    blocks: np.ndarray


def readable_extensions() -> tuple[str, ...]:
    """Extensions (with the dot) pyembroidery can read."""
    return tuple("." + f["extension"] for f in pyembroidery.supported_formats() if f.get("reader"))


def read_embroidery(path: str | os.PathLike) -> EmbroideryFile:
    """Read `path` with pyembroidery; coordinates in mm, +y down."""
    path = str(path)
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in readable_extensions():
        raise InputError(f"cannot read {path!r} as embroidery; pyembroidery reads "
                         f"{', '.join(readable_extensions())}")
    check_input_file(path, what="embroidery file", expect=f"a {suffix} file")
    try:
        pattern = pyembroidery.read(path)
    except Exception as error:  # pyembroidery raises anything on a corrupt file
        # pyembroidery's exception text is its own internals (an index, a struct size): not
        # worth showing; what the user needs is that the file is not what its name says.
        raise InputError(f"cannot read {path!r}: it is not a valid {suffix} file (damaged, truncated or "
                         "another format)") from None
    if pattern is None or not pattern.stitches:
        raise InputError(f"{path!r} holds no stitches pyembroidery can read")
    rows = np.asarray(pattern.stitches, dtype=float).reshape(-1, 3)
    command = rows[:, 2].astype(np.int64) & pyembroidery.COMMAND_MASK
    kinds = np.full(len(rows), 255, dtype=np.uint8)
    kinds[command == pyembroidery.STITCH] = STITCH
    kinds[command == pyembroidery.JUMP] = JUMP
    kinds[np.isin(command, _CUTS)] = TRIM
    keep = kinds != 255
    if not (kinds == STITCH).any():
        raise InputError(f"{path!r} holds no stitches pyembroidery can read")
    is_change = np.isin(command, (pyembroidery.COLOR_CHANGE, pyembroidery.NEEDLE_SET))
    changes = int(is_change.sum())
    blocks = np.cumsum(is_change)[keep]
    points, kinds = rows[keep, :2] / 10.0, kinds[keep]
    params = np.linspace(0.0, 1.0, len(points)) if len(points) > 1 else np.zeros(len(points))
    params[kinds != STITCH] = np.nan
    threads = tuple(tuple(int(v) for v in (t.get_red(), t.get_green(), t.get_blue()))
                    for t in pattern.threadlist) or ((0, 0, 0),)
    plan = StitchPlan(points=points, kinds=kinds, roles=np.full(len(points), BODY, dtype=np.uint8),
                      params=params, strokes=np.where(kinds == STITCH, 0, -1),
                      threads=tuple(Thread(color=c) for c in threads), blocks=blocks)
    return EmbroideryFile(plan=plan, threads=threads, color_changes=changes, blocks=blocks)
