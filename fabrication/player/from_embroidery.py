"""Player rows from a stitch plan or an embroidery file, timed like `embroidery_stats`.

Time model (the one the stats print): every needle point takes 60 / stitches_per_minute
s, every trim and every colour change `trim_seconds` (a colour change read from a file is
a TRIM row of the plan that is also counted as a colour change, so it costs both, as in
the stats), jumps take no time.
"""

from __future__ import annotations

import os

import numpy as np

from fabrication.embroidery.plan import COLOR as PLAN_COLOR
from fabrication.embroidery.plan import STITCH, TRIM, StitchPlan
from fabrication.embroidery.stats import EmbroideryStats, embroidery_stats
from fabrication.player.data import COLOR, DOWN, DRAW, TRAVEL, PlayerData, hex_color
from fabrication.player.data import TRIM as ROW_TRIM

# Threads for colour blocks a file names no colour for (DST has no colours at all).
_FILLER = ((20, 20, 20), (200, 30, 40), (30, 90, 200), (20, 150, 70), (230, 150, 20),
           (140, 50, 160), (0, 150, 170), (120, 80, 40))


def stitch_player_data(plan: StitchPlan, *, title: str = "stitches",
                       blocks: np.ndarray | None = None,
                       threads: tuple[tuple[int, int, int], ...] | None = None,
                       stitches_per_minute: float = 600.0, trim_seconds: float = 10.0,
                       hoop: tuple[float, float, float, float] | None = None,
                       stats: EmbroideryStats | None = None) -> PlayerData:
    """`PlayerData` of a stitch plan (mm, +y down).

    blocks (N,) int: colour block of each row (None: the plan's own `blocks`). threads:
    RGB per block (None: the plan's threads; blocks past the end get filler colours).
    A colour change is a COLOR row of the plan, or (in a file read back) a TRIM row whose
    block differs from the previous row's. hoop: (xmin, ymin, xmax, ymax) mm outline.
    stats: the plan's stats for the info lines (None: measured here).
    """
    kinds_in = np.asarray(plan.kinds)
    n = len(kinds_in)
    blocks = np.asarray(plan.blocks if blocks is None else blocks, dtype=np.int64)
    threads = tuple(threads) if threads else tuple(tuple(t.color) for t in plan.threads)
    change = np.zeros(n, dtype=bool)
    change[1:] = blocks[1:] != blocks[:-1]
    change[:1] = blocks[:1] != 0
    trim = kinds_in == TRIM
    colour = (kinds_in == PLAN_COLOR) | (trim & change)
    stitch = kinds_in == STITCH
    previous_stitch = np.r_[False, stitch[:-1]]
    kinds = np.full(n, TRAVEL, dtype=np.uint8)  # JUMP rows stay TRAVEL
    kinds[stitch & previous_stitch] = DRAW
    kinds[stitch & ~previous_stitch] = DOWN
    kinds[trim] = ROW_TRIM
    kinds[colour] = COLOR

    # cumulative counts, then the stats' own expression, so the last time is its figure
    needles = np.cumsum(stitch)
    cuts = np.cumsum(trim) + np.cumsum(colour)
    times = needles / stitches_per_minute * 60.0 + cuts * trim_seconds

    used = int(blocks.max()) + 1 if n else 1
    palette = tuple(hex_color(threads[b] if b < len(threads) else _FILLER[b % len(_FILLER)])
                    for b in range(used))
    if stats is None:
        stats = embroidery_stats(plan, stitches_per_minute=stitches_per_minute,
                                 trim_seconds=trim_seconds, color_changes=int(colour.sum()))
    return PlayerData(
        source="embroidery", title=title, points=np.asarray(plan.points, dtype=float), kinds=kinds,
        colors=blocks, palette=palette, times=times, numbers=needles, number_label="stitch",
        number_total=int(needles[-1]) if n else 0, total=float(stats.seconds), unit="mm",
        time_unit="s", frame=hoop, info=tuple(stats.lines()), warnings=stats.warnings)


def embroidery_file_player_data(path: str | os.PathLike, *, stitches_per_minute: float = 600.0,
                                trim_seconds: float = 10.0,
                                hoop: tuple[float, float, float, float] | None = None) -> PlayerData:
    """`PlayerData` of an embroidery file pyembroidery reads (.pes, .dst, .jef, .exp, .vp3, ...)."""
    from fabrication.embroidery.read import read_embroidery

    read = read_embroidery(path)
    stats = embroidery_stats(read.plan, stitches_per_minute=stitches_per_minute,
                             trim_seconds=trim_seconds, color_changes=read.color_changes)
    return stitch_player_data(read.plan, title=os.path.basename(str(path)), blocks=read.blocks,
                              threads=read.threads, stitches_per_minute=stitches_per_minute,
                              trim_seconds=trim_seconds, hoop=hoop, stats=stats)
