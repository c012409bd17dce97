"""Whole-design assembly: stitch every stroke, add tacks, locks, trims and jumps, then make
the needle points safe to sew.

Per stroke: generator needle points, a tack at the start and a lock at the end. Between
strokes further apart than `trim_distance`: trim, jump, tack; closer ones are joined by a
short travel stitch. Finally the points are snapped to the files' 0.1 mm grid and, on
that grid, stitches shorter than `min_stitch` are merged away (locks excepted, zero
length never) and needle-down stitches longer than `max_stitch` per axis are split into
real stitches. Snapping here rather than in the writer is deliberate: the minimum,
maximum and no-zero-length guarantees must hold for the points the machine will sew,
and the writer's rounding of points already on the grid is then exact.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Union

import numpy as np
from scipy.spatial import cKDTree

from fabrication.embroidery.arrows import ArrowOptions, arrow_stitch
from fabrication.embroidery.grid import merge_short, split_long
from fabrication.embroidery.locks import (TIE_LEVELS, LighterTie, LockOptions, crowding_ties, lock_points,
                                          tack_points)
from fabrication.embroidery.needles import (COLOR, GRID, JUMP, LOCK, LONGEST_STITCH, STITCH, TACK, TRAVEL,
                                            TRIM, NeedlePoints)
from fabrication.embroidery.order import Start, check_start, sewing_order
from fabrication.embroidery.running import STITCH_LENGTH, RunningOptions, running_stitch
from fabrication.embroidery.satin import SatinOptions, satin_stitch
from fabrication.embroidery.thread import RGB, Thread, check_chart
from fabrication.embroidery.triple import TripleOptions, triple_stitch
from fabrication.embroidery.zigzag import ZigzagOptions, zigzag_stitch
from onestroke.errors import FabricationError, InputError
from onestroke.progress import ProgressCallback, Stage
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

StyleOptions = Union[RunningOptions, TripleOptions, ZigzagOptions, SatinOptions, ArrowOptions]

# STITCH, JUMP, TRIM, COLOR: the row kinds of a plan (defined in `needles`, used from here).
# A fixed JEF date (YYYYMMDDhhmmss) so files are the same bytes from run to run; callers
# pass the build's own date (SOURCE_DATE_EPOCH) through `StitchPlan.date`.
FIXED_DATE = "20000101000000"

# Style name -> options class; the generator for each class is in _GENERATORS.
STYLES: dict[str, type] = {
    "running": RunningOptions,
    "triple": TripleOptions,
    "zigzag": ZigzagOptions,
    "satin": SatinOptions,
    "arrows": ArrowOptions,
}

_GENERATORS: dict[type, Callable[[Stroke, object, float], NeedlePoints]] = {
    RunningOptions: lambda stroke, o, offset: running_stitch(stroke, o),
    TripleOptions: lambda stroke, o, offset: triple_stitch(stroke, o),
    ZigzagOptions: lambda stroke, o, offset: zigzag_stitch(stroke, o),
    # the stroke's place along the design seeds its randomness (same options, same bytes)
    SatinOptions: lambda stroke, o, offset: satin_stitch(stroke, o, seed=int(round(offset * 1000))),
    ArrowOptions: lambda stroke, o, offset: arrow_stitch(stroke, o, offset=offset),
}

# Design-wide rules, mm (a stitch under one grid step is no stitch in the files).
MIN_STITCH = Range(GRID, 3.0, unit="mm", name="--min-stitch")
MAX_STITCH = Range(1.0, LONGEST_STITCH, unit="mm", name="--max-stitch")
TRIM_DISTANCE = Range(0.0, 1000.0, unit="mm", name="--trim-distance")
MIN_STROKE = Range(0.0, 100.0, unit="mm", name="--min-stroke")
GRID_STEP = Range(0.0, None, unit="mm", name="grid", low_open=True)


def style_class(name: str) -> type:
    """The options class of the style `name` ('running', 'triple', 'zigzag', 'satin', 'arrows')."""
    cls = STYLES.get(str(name).lower())
    if cls is None:
        raise InputError(f"unknown stitch style {name!r}; use one of {', '.join(STYLES)}")
    return cls


def style_options(name: str, **values) -> StyleOptions:
    """Options of the style `name` ('running', 'triple', 'zigzag', 'satin', 'arrows'); `values` that
    are None are left at the style's default."""
    cls = style_class(name)
    fields = cls.__dataclass_fields__
    return cls(**{k: v for k, v in values.items() if v is not None and k in fields})


def style_reach(style: StyleOptions, drawing: Drawing | None = None) -> float:
    """How far needle points may stray from the curve, mm (for hoop checks); a satin's
    reach follows the widest ink of `drawing` (mm)."""
    if isinstance(style, ZigzagOptions):
        return style.reach
    if isinstance(style, SatinOptions):
        return style.reach(widest_ink(drawing) if drawing is not None else style.max_width)
    if isinstance(style, ArrowOptions):
        return style.width / 2.0
    return 0.0


def widest_ink(drawing: Drawing) -> float:
    """The widest ink of `drawing` along any stroke (its stroke width where unknown), in its unit."""
    return max([float(s.widths[:, 1].max()) for s in drawing.strokes if s.widths is not None]
               + [float(drawing.stroke_width)])


def with_known_widths(drawing: Drawing) -> Drawing:
    """`drawing` whose strokes without an ink width take the drawing's stroke width."""
    if all(s.widths is not None for s in drawing.strokes):
        return drawing
    w = float(drawing.stroke_width)
    return drawing.with_strokes(s if s.widths is not None else s.with_widths(np.array([[0.0, w], [1.0, w]]))
                                for s in drawing.strokes)


@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """style: options of one stitch style; lock: tack and lock form; min_stitch: shortest
    stitch outside locks, mm; max_stitch: longest needle-down move per axis, mm;
    trim_distance: strokes further apart are trimmed and jumped, mm; min_stroke: shorter
    strokes are joined to a neighbour within the trim distance by travel stitches, or
    dropped, mm; color: thread RGB of strokes without a colour of their own; colors: one
    RGB per stroke in drawing order (overrides the strokes' colours; the last repeats);
    thread_chart: catalogue the threads are picked from (see `thread.THREAD_CHARTS`);
    start: None, 'reverse' or a point (x, y) mm where sewing starts; grid: the files'
    coordinate step, mm."""

    style: StyleOptions = field(default_factory=RunningOptions)
    lock: LockOptions = field(default_factory=LockOptions)
    min_stitch: float = ranged(0.3, MIN_STITCH)
    max_stitch: float = ranged(12.1, MAX_STITCH)
    trim_distance: float = ranged(3.0, TRIM_DISTANCE)
    min_stroke: float = ranged(1.0, MIN_STROKE)
    color: RGB = (0, 0, 0)
    colors: tuple[RGB, ...] = ()
    thread_chart: str | None = None
    start: Start = None
    grid: float = ranged(GRID, GRID_STEP)

    def __post_init__(self) -> None:
        check_ranges(self)
        if type(self.style) not in _GENERATORS:
            raise InputError(f"unknown stitch style options {type(self.style).__name__}")
        if not self.min_stitch >= self.grid:
            raise InputError(f"--min-stitch {self.min_stitch:g} mm must be at least the grid {self.grid:g} mm")
        if not self.max_stitch > 2 * self.min_stitch:
            raise InputError(f"--max-stitch {self.max_stitch:g} mm must exceed twice --min-stitch "
                             f"{self.min_stitch:g} mm")
        walk = getattr(self.style, "stitch_length", None)
        if walk is not None and walk < self.min_stitch:
            raise InputError(f"--stitch-length {walk:g} mm is shorter than --min-stitch {self.min_stitch:g} mm, "
                             "so every stitch would be merged away; lengthen it or lower --min-stitch")
        for rgb in (self.color, *self.colors):
            Thread(color=rgb)  # validates
        if self.thread_chart is not None:
            object.__setattr__(self, "thread_chart", check_chart(self.thread_chart))
        object.__setattr__(self, "start", check_start(self.start))


@dataclass(frozen=True, eq=False)
class StitchPlan:
    """Rows in sewing order. points (N, 2) mm on the 0.1 mm grid; kinds (N,) STITCH (needle
    down here), JUMP (move here needle up), TRIM (cut at the current point) or COLOR (next
    thread); roles (N,) needle roles (BODY, TACK, LOCK, ...); params (N,): stroke index +
    curve parameter t (NaN on jumps and trims); strokes (N,): index of the sewn stroke each
    row sews (-1 on trims and jumps); threads: one per colour block; blocks (N,): colour
    block of each row (None: all 0); sewn: the strokes as sewn (rows index into it);
    dropped: one line per stroke left out; lighter: the tacks and locks made lighter (or
    left out) because they would have crowded their place beyond the density limit; name:
    the design name files store; field: the hoop (width, height) mm the design is meant
    for; date: YYYYMMDDhhmmss for JEF."""

    points: np.ndarray
    kinds: np.ndarray
    roles: np.ndarray
    params: np.ndarray
    strokes: np.ndarray
    threads: tuple[Thread, ...] = (Thread(color=(0, 0, 0)),)
    blocks: np.ndarray | None = None
    sewn: Drawing | None = None
    dropped: tuple[str, ...] = ()
    lighter: tuple[LighterTie, ...] = ()
    name: str = "onestroke"
    field: tuple[float, float] | None = None
    date: str = FIXED_DATE

    def __post_init__(self) -> None:
        if self.blocks is None:
            object.__setattr__(self, "blocks", np.zeros(len(self.points), dtype=np.int64))

    def __len__(self) -> int:
        return len(self.points)

    @property
    def color(self) -> RGB:
        """RGB of the first thread."""
        return self.threads[0].color

    @property
    def skipped(self) -> int:
        """How many strokes were left out."""
        return len(self.dropped)

    @property
    def color_changes(self) -> int:
        return int((self.kinds == COLOR).sum())

    @property
    def needle_mask(self) -> np.ndarray:
        """(N,) True on needle-down rows."""
        return self.kinds == STITCH

    @property
    def stitch_mask(self) -> np.ndarray:
        """(N,) True on rows that end a needle-down stitch (a STITCH right after a STITCH)."""
        mask = np.zeros(len(self.kinds), dtype=bool)
        mask[1:] = (self.kinds[1:] == STITCH) & (self.kinds[:-1] == STITCH)
        return mask

    def stitches(self) -> tuple[np.ndarray, np.ndarray]:
        """Needle-down stitches as (start (S, 2), end (S, 2)) in mm."""
        end = np.flatnonzero(self.stitch_mask)
        return self.points[end - 1], self.points[end]

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) mm of every needle point and jump target."""
        pts = self.points[self.kinds <= JUMP]
        if not len(pts):
            return (0.0, 0.0, 0.0, 0.0)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def _lock_paths(body: NeedlePoints) -> tuple[np.ndarray, np.ndarray]:
    """The paths tacks and locks walk along: from the start, the needle points that move
    forward along the curve (parameter above all before); to the end, those that move
    back along it. Triple stitch's back-and-forth and arrow arms drop out, so a lock lies
    on the sewn line instead of folding over one short stitch."""
    t = body.t
    ahead = np.ones(len(t), dtype=bool)
    ahead[1:] = t[1:] > np.maximum.accumulate(t)[:-1]
    back = np.ones(len(t), dtype=bool)
    rt = t[::-1]
    back[1:] = rt[1:] < np.minimum.accumulate(rt)[:-1]
    return body.points[ahead], body.points[::-1][back][::-1]


def _chains(drawing: Drawing, block: tuple[int, ...], options: PlanOptions) -> tuple[list[list[int]], list[int]]:
    """Group sewn strokes into chains sewn with one tack and one lock. A stroke shorter
    than `min_stroke` joins its nearer neighbour in sewing order (same thread, within the
    trim distance) by a travel stitch; a chain still shorter than `min_stroke` in all is
    dropped (a knot of tacks and locks on a speck). Returns the chains and the dropped
    strokes."""
    strokes = drawing.strokes
    n = len(strokes)
    lengths = [s.length for s in strokes]
    gap = [np.inf] + [float(np.linalg.norm(strokes[i].start - strokes[i - 1].end))
                      if block[i] == block[i - 1] else np.inf for i in range(1, n)]
    joined = [False] * n  # joined[i]: stroke i continues the chain of stroke i - 1
    for i in range(n):
        if lengths[i] >= options.min_stroke:
            continue
        before = gap[i]
        after = gap[i + 1] if i + 1 < n else np.inf
        if before <= options.trim_distance and before <= after:
            joined[i] = True
        elif after <= options.trim_distance:
            joined[i + 1] = True
    chains: list[list[int]] = []
    for i in range(n):
        if joined[i] and chains:
            chains[-1].append(i)
        else:
            chains.append([i])
    kept, dropped = [], []
    for chain in chains:
        if sum(lengths[i] for i in chain) >= max(options.min_stroke, options.min_stitch):
            kept.append(chain)
        else:
            dropped += chain
    return kept, dropped


def _dropped_lines(drawing: Drawing, dropped: list[int], block: tuple[int, ...], source: tuple[int, ...],
                   points: np.ndarray, blocks: np.ndarray, options: PlanOptions) -> tuple[str, ...]:
    """One line per dropped stroke (numbered as in the input), with the distance from it to
    the nearest needle point of its thread in the plan (`points` (N, 2) mm, `blocks` (N,)
    of the needle rows)."""
    lines, trees = [], {}
    for i in dropped:
        stroke = drawing.strokes[i]
        if block[i] not in trees:
            mine = points[blocks == block[i]]
            trees[block[i]] = cKDTree(mine) if len(mine) else None
        along = stroke.points_at(np.linspace(0.0, 1.0, 9))
        near = float(trees[block[i]].query(along)[0].min()) if trees[block[i]] is not None else np.inf
        x, y = stroke.start
        if near > options.trim_distance:
            why = (f"more than --trim-distance {options.trim_distance:g} mm from every stitch of its "
                   f"thread (the nearest is {near:.1f} mm away)" if np.isfinite(near) else
                   "no stitch of its thread is sewn")
        else:
            why = (f"the strokes sewn before and after it end more than --trim-distance "
                   f"{options.trim_distance:g} mm away (the nearest stitch of its thread, {near:.1f} mm "
                   "away, is in the middle of a stroke)")
        lines.append(f"stroke {source[i] + 1} ({stroke.length:.2f} mm at {x:.1f}, {y:.1f} mm) was left out: "
                     f"shorter than --min-stroke {options.min_stroke:g} mm and {why}")
    return tuple(lines)


def _chain_points(drawing: Drawing, chain: list[int], options: PlanOptions, offset: float):
    """Needle points of one chain: each long stroke by the style's generator, short ones
    as a plain running stitch with the TRAVEL role; params are stroke index + t."""
    generate = _GENERATORS[type(options.style)]
    parts, params, owners = [], [], []
    for index in chain:
        stroke = drawing.strokes[index]
        if stroke.length >= options.min_stroke:
            body = generate(stroke, options.style, offset)
        else:
            length = min(max(options.min_stroke, 0.5), STITCH_LENGTH.high)  # one stitch, or the longest
            walk = running_stitch(stroke, RunningOptions(stitch_length=length))
            body = NeedlePoints.of(walk.points, walk.t, TRAVEL)
        offset += stroke.length
        parts.append(body)
        params.append(index + body.t)
        owners.append(np.full(len(body), index, dtype=np.int64))
    merged = NeedlePoints.concat(parts)
    # Monotone parameters over the chain let the lock paths follow it from stroke to stroke.
    merged = NeedlePoints(merged.points, np.concatenate(params), merged.roles)
    return merged, np.concatenate(owners), offset


def _stitch_chains(drawing: Drawing, block: tuple[int, ...], options: PlanOptions, progress=None):
    """The chains (see `_chains`), each chain's needle points and stroke owners, and the
    lines about dropped strokes. `progress`: reports per stroke stitched."""
    chains, dropped = _chains(drawing, block, options)
    report = Stage(progress, "stitching", sum(len(chain) for chain in chains), "strokes")
    bodies, offset = [], 0.0
    for chain in chains:
        body, owner, offset = _chain_points(drawing, chain, options, offset)
        bodies.append((body, owner))
        report.advance(len(chain))
    report.finish()
    if not chains:
        raise InputError("no stroke is long enough to stitch (all shorter than --min-stroke "
                         f"{options.min_stroke:g} mm and far from the others)")
    return chains, bodies, dropped


def _assemble(chains: list[list[int]], bodies: list, block: tuple[int, ...], options: PlanOptions,
              levels: dict[int, int], made: dict[tuple[int, int], np.ndarray]):
    """Rows before cleanup: float points, kinds, roles, params, owners, blocks, ties; and
    the anchor of each tie (where a tack starts, a lock ends). ties (N,): 2 c on the tack
    of the c-th chain, 2 c + 1 on its lock, -1 elsewhere; `levels` maps a tie to its level
    (see `locks`; 0 when absent); `made` keeps the ties' points from round to round."""
    pts, kinds, roles, params, owners, blocks, ties = [], [], [], [], [], [], []
    anchors: list[np.ndarray] = []  # anchors[tie]: where the tack starts / the lock ends
    current: np.ndarray | None = None
    current_block = block[0] if block else 0

    def add(p, kind, role, param, owner, tie=-1):
        p = np.atleast_2d(p)
        owners.append(np.broadcast_to(np.asarray(owner, dtype=np.int64), (len(p),)))
        pts.append(p)
        kinds.append(np.full(len(p), kind, dtype=np.uint8))
        roles.append(np.broadcast_to(np.asarray(role, dtype=np.uint8), (len(p),)))
        params.append(np.broadcast_to(np.asarray(param, dtype=float), (len(p),)))
        blocks.append(np.full(len(p), current_block, dtype=np.int64))
        ties.append(np.full(len(p), tie, dtype=np.int64))

    def tie_points(tie: int, make, path: np.ndarray) -> np.ndarray:
        key = (tie, levels.get(tie, 0))
        if key not in made:
            made[key] = make(path, options.lock, key[1])
        return made[key]

    for c, (chain, (body, owner)) in enumerate(zip(chains, bodies)):
        path = body.points
        connect = TACK
        if current is None:
            current_block = block[chain[0]]
        else:
            if block[chain[0]] != current_block:
                add(current, TRIM, TRAVEL, np.nan, -1)
                current_block = block[chain[0]]
                add(current, COLOR, TRAVEL, np.nan, -1)
                add(path[0], JUMP, TRAVEL, np.nan, -1)
            elif np.linalg.norm(path[0] - current) > options.trim_distance:
                add(current, TRIM, TRAVEL, np.nan, -1)
                add(path[0], JUMP, TRAVEL, np.nan, -1)
            else:
                connect = TRAVEL  # a short stitch from the last stroke's end
        head, tail = _lock_paths(body)
        first, last = chain[0], chain[-1]
        anchors += [path[0], path[-1]]
        tack = tie_points(2 * c, tack_points, head)
        body_roles = body.roles.copy()
        if len(tack):
            add(tack, STITCH, [connect] + [TACK] * (len(tack) - 1), body.t[0], first, 2 * c)
            body_roles[0] = TACK  # the stitch into the start closes the tack
        elif connect == TRAVEL:
            body_roles[0] = TRAVEL
        add(path, STITCH, body_roles, body.t, owner)
        lock = tie_points(2 * c + 1, lock_points, tail)
        if len(lock):
            add(lock, STITCH, LOCK, body.t[-1], last, 2 * c + 1)
        current = path[-1]
    return (np.concatenate(pts), np.concatenate(kinds), np.concatenate(roles), np.concatenate(params),
            np.concatenate(owners), np.concatenate(blocks), np.concatenate(ties), anchors)


def _on_grid(rows, options: PlanOptions):
    """Rows of `_assemble` snapped to the grid (integer units), short stitches merged away
    and long ones split: units, kinds, roles, params, owners, blocks, ties."""
    points, kinds, roles, params, owners, blocks, ties = rows
    units = np.rint(points / options.grid).astype(np.int64)
    keep = merge_short(units, kinds, roles, options.min_stitch / options.grid - 1e-9)
    max_units = int(np.floor(options.max_stitch / options.grid + 1e-9))
    units, params, source = split_long(units[keep], kinds[keep], params[keep], max_units)
    kinds, roles, owners, blocks, ties = (a[keep][source] for a in (kinds, roles, owners, blocks, ties))
    return units, kinds, roles, params, owners, blocks, ties


def _centring_shift(units: np.ndarray, kinds: np.ndarray) -> np.ndarray:
    """Whole grid steps (2,) that centre the box of the needle points and jumps on (0, 0)
    (to within half a step)."""
    box = units[kinds <= JUMP]
    return -np.rint((box.min(axis=0) + box.max(axis=0)) / 2).astype(np.int64)


def plan_embroidery(drawing: Drawing, options: PlanOptions = PlanOptions(), *,
                    progress: ProgressCallback | None = None, centre: bool = False) -> StitchPlan:
    """Stitch every stroke of `drawing` (mm, centred on (0, 0)) into one `StitchPlan`:
    colour blocks in sewing order (see `order.sewing_order`), rows indexing `plan.sewn`.
    progress: an `onestroke.progress.ProgressCallback` (strokes stitched); centre: move
    the stitches (and `plan.sewn`) by whole grid steps so that the bounding box of the
    needle points and jumps is centred on (0, 0) (the curve's box is not the stitches': a
    zigzag or arrows reach further on one side of it)."""
    if drawing.unit != "mm":
        raise InputError(f"place the drawing in mm before stitching (it is in {drawing.unit})")
    if not drawing.strokes:
        raise InputError("the drawing has no strokes to stitch")
    if isinstance(options.style, SatinOptions):
        drawing = with_known_widths(drawing)  # a satin is as wide as its stroke's ink
    order = sewing_order(drawing, colors=options.colors, default=options.color,
                         start=options.start, thread_chart=options.thread_chart)
    sewn = order.drawing
    # Tacks and locks that crowd a place beyond the density limit get lighter, one level
    # per round (full, single, none; tacks before locks), until none does: short strokes
    # never knot. A plan without crowding is made once.
    chains, bodies, dropped = _stitch_chains(sewn, order.block, options, progress)
    levels: dict[int, int] = {}
    made: dict[tuple[int, int], np.ndarray] = {}
    for _ in range(2 * TIE_LEVELS):
        *rows, anchors = _assemble(chains, bodies, order.block, options, levels, made)
        units, kinds, roles, params, owners, blocks, ties = _on_grid(rows, options)
        lighter = crowding_ties(units * options.grid, kinds, ties, levels)
        if not lighter:
            break
        levels.update({tie: levels.get(tie, 0) + 1 for tie in lighter})
    if not np.any(kinds == STITCH):
        raise FabricationError("no needle points left after merging short stitches")
    shift = _centring_shift(units, kinds) if centre else np.zeros(2, dtype=np.int64)
    if shift.any():
        units = units + shift
        dx, dy = shift * options.grid
        sewn = sewn.transformed(np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]]), width=sewn.width,
                                height=sewn.height, unit=sewn.unit, stroke_width=sewn.stroke_width)
    needle = kinds == STITCH
    dropped = _dropped_lines(sewn, dropped, order.block, order.source, units[needle] * options.grid,
                             blocks[needle], options)
    used = np.unique(blocks)
    # A block whose strokes were all dropped has no thread in the file.
    remap = np.full(len(order.threads), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    lighter = tuple(LighterTie(x=float(x), y=float(y), lock=bool(tie % 2), level=level)
                    for tie, level in sorted(levels.items())
                    for x, y in [(np.rint(anchors[tie] / options.grid) + shift) * options.grid])
    return StitchPlan(points=units * options.grid, kinds=kinds, roles=roles, params=params,
                      strokes=owners, threads=tuple(order.threads[i] for i in used),
                      blocks=remap[blocks], sewn=sewn, dropped=dropped, lighter=lighter)
