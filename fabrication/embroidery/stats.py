"""Stats of a stitch plan: counts, thread, size, sewing time and a density check.

Thread: the top thread is the sum of the needle-down stitch lengths. The bobbin thread is
an estimate from the lockstitch's balance: under a running stitch (walks, triple stitch,
arrows, tacks, locks, travel) the bobbin lies along the back of every stitch, as long as
the top thread; under a column (zigzag, satin) the top thread is pulled round to the back
and the bobbin shows only in the middle third, so the column's body stitches count a third
(`COLUMN_BOBBIN_SHARE`; the embroiderers' rule of 2/3 top, 1/3 bobbin for satin). Neither
counts the thread inside the fabric or the tails at trims.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabrication.embroidery.needles import BODY, JUMP, STITCH, TRIM
from fabrication.embroidery.plan import StitchPlan
from fabrication.embroidery.quality import DENSITY_LIMIT, DENSITY_RADIUS, Place, needle_density, where

COLUMN_BOBBIN_SHARE = 1.0 / 3.0
from fabrication.embroidery.thread import Thread


@dataclass(frozen=True, kw_only=True)
class ColorStats:
    """One colour block: its thread, needle penetrations, thread length (mm) and the
    sewing time of its stitches and trims (s; the colour change itself counts in the total)."""

    thread: Thread
    stitches: int
    thread_length: float
    seconds: float


@dataclass(frozen=True, kw_only=True)
class EmbroideryStats:
    """stitches: needle penetrations; jumps: needle-up moves (a split jump counts once,
    the lead-in to the first point not at all); trims; color_changes; thread_length: sum
    of needle-down stitch lengths, mm; width / height: extent of the needle points, mm;
    seconds: estimated sewing time; max_density: most needle points within
    `density_radius` of one needle point (every needle point counted, tacks and locks
    included, itself too); dense_points: needle points with more than `density_limit`;
    bobbin_length: the bobbin thread, mm, estimated by `bobbin_rule` (see the module);
    dense_places: where (densest first); density_advice: what to change there (the
    style's option); lighter_tacks / lighter_locks: tacks and locks the planner made
    lighter or left out so as not to crowd a place (`StitchPlan.lighter`); colors: per
    block."""

    stitches: int
    jumps: int
    trims: int
    color_changes: int
    thread_length: float
    width: float
    height: float
    seconds: float
    stitches_per_minute: float
    max_density: int
    dense_points: int
    density_radius: float
    density_limit: int
    dense_places: tuple[Place, ...] = ()
    density_advice: str = "use a longer stitch or a wider spacing"
    lighter_tacks: int = 0
    lighter_locks: int = 0
    bobbin_length: float = 0.0
    bobbin_rule: str = "as long as the top"
    colors: tuple[ColorStats, ...] = ()

    @property
    def too_dense(self) -> bool:
        return self.dense_points > 0

    @property
    def warnings(self) -> tuple[str, ...]:
        if not self.too_dense:
            return ()
        return (f"too dense: up to {self.max_density} needle points within {self.density_radius:g} mm "
                f"(more than {self.density_limit}; every needle point counted, tacks and locks included) "
                f"{where(self.dense_places)}; the thread may pile up or break; {self.density_advice}",)

    def lines(self) -> list[str]:
        """Human-readable lines (for the CLI and the preview's corner)."""
        minutes, seconds = divmod(int(round(self.seconds)), 60)
        return [
            f"stitches  {self.stitches:,}",
            f"jumps     {self.jumps}   trims {self.trims}",
            f"thread    {self.thread_length / 1000:.2f} m top, about {self.bobbin_length / 1000:.2f} m bobbin "
            f"({self.bobbin_rule})",
            f"size      {self.width:.1f} x {self.height:.1f} mm",
            f"time      {minutes} min {seconds:02d} s at {self.stitches_per_minute:g} spm",
            f"density   max {self.max_density} within {self.density_radius:g} mm, every needle point"
            + ("  TOO DENSE" if self.too_dense else ""),
        ] + self.tie_lines() + self.color_lines()

    def tie_lines(self) -> list[str]:
        """A line when tacks or locks were made lighter for density (none otherwise)."""
        if not (self.lighter_tacks or self.lighter_locks):
            return []
        return [f"ties      {self.lighter_tacks} tacks and {self.lighter_locks} locks lighter or left out "
                f"(they would have put more than {self.density_limit} needle points within "
                f"{self.density_radius:g} mm)"]

    def color_lines(self) -> list[str]:
        """One line per colour block: thread (catalogue number), stitches, thread, time."""
        lines = []
        for k, c in enumerate(self.colors, start=1):
            minutes, seconds = divmod(int(round(c.seconds)), 60)
            lines.append(f"colour {k}  {c.thread.label}: {c.stitches:,} stitches, "
                         f"{c.thread_length / 1000:.2f} m, {minutes} min {seconds:02d} s")
        return lines


def embroidery_stats(plan: StitchPlan, *, stitches_per_minute: float = 600.0,
                     trim_seconds: float = 10.0, color_changes: int | None = None,
                     density_radius: float = DENSITY_RADIUS, density_limit: int = DENSITY_LIMIT,
                     density_advice: str | None = None, column: bool = False) -> EmbroideryStats:
    """Measure `plan`. Time = stitches / stitches_per_minute + (trims + colour changes) x
    trim_seconds; colour changes default to the plan's own. density_advice: what the
    density warning tells the user to change (default: a longer stitch or a wider spacing);
    column: the body stitches cross a column (zigzag, satin): the bobbin under them is a
    third of their length (see the module)."""
    if color_changes is None:
        color_changes = plan.color_changes
    needles = plan.points[plan.kinds == STITCH]
    a, b = plan.stitches()
    thread = float(np.linalg.norm(b - a, axis=1).sum()) if len(a) else 0.0
    share = np.ones(len(a))
    if column:
        share[plan.roles[plan.stitch_mask] == BODY] = COLUMN_BOBBIN_SHARE
    bobbin = float(np.linalg.norm(b - a, axis=1) @ share) if len(a) else 0.0
    rule = "1/3 of the top under the column, all under walks" if column else "as long as the top"
    kinds = plan.kinds
    is_jump = kinds == JUMP
    run_start = is_jump & np.concatenate([[True], ~is_jump[:-1]])
    first_needle = int(np.argmax(kinds == STITCH)) if len(needles) else len(kinds)
    jumps = int(run_start[first_needle:].sum())
    trims = int((kinds == TRIM).sum())
    # Every needle point counts: a knot of tacks and locks is as dense as any other.
    density = needle_density(needles, radius=density_radius, limit=density_limit)
    if len(needles):
        lo, hi = needles.min(axis=0), needles.max(axis=0)
    else:
        lo, hi = np.zeros(2), np.zeros(2)
    seconds = len(needles) / stitches_per_minute * 60.0 + (trims + color_changes) * trim_seconds
    colors = []
    stitch_end = np.flatnonzero(plan.stitch_mask)
    lengths = np.linalg.norm(b - a, axis=1) if len(a) else np.zeros(0)
    for k, spool in enumerate(plan.threads):
        mine = plan.blocks == k
        count = int((mine & (kinds == STITCH)).sum())
        block_trims = int((mine & (kinds == TRIM)).sum())
        colors.append(ColorStats(thread=spool, stitches=count,
                                 thread_length=float(lengths[mine[stitch_end]].sum()),
                                 seconds=count / stitches_per_minute * 60.0 + block_trims * trim_seconds))
    return EmbroideryStats(stitches=int(len(needles)), jumps=jumps, trims=trims,
                           color_changes=int(color_changes), thread_length=thread,
                           width=float(hi[0] - lo[0]), height=float(hi[1] - lo[1]),
                           seconds=float(seconds), stitches_per_minute=float(stitches_per_minute),
                           max_density=density.maximum, dense_points=density.dense,
                           density_radius=density_radius, density_limit=density_limit,
                           dense_places=density.places, colors=tuple(colors),
                           bobbin_length=bobbin, bobbin_rule=rule,
                           lighter_tacks=sum(not t.lock for t in plan.lighter),
                           lighter_locks=sum(t.lock for t in plan.lighter),
                           **({"density_advice": density_advice} if density_advice else {}))
