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

import heapq
from dataclasses import dataclass, field
from typing import Callable, Union

import numpy as np

from fabrication.embroidery.arrows import ArrowOptions, arrow_stitch
from fabrication.embroidery.locks import LockOptions, lock_points, tack_points
from fabrication.embroidery.needles import (BODY, LOCK, MOTIF, TACK, TRAVEL, UNDERLAY,
                                            NeedlePoints)
from fabrication.embroidery.running import RunningOptions, running_stitch
from fabrication.embroidery.triple import TripleOptions, triple_stitch
from fabrication.embroidery.zigzag import ZigzagOptions, zigzag_stitch
from onestroke.errors import FabricationError, InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

StyleOptions = Union[RunningOptions, TripleOptions, ZigzagOptions, ArrowOptions]

# Row kinds of a plan (mapped to pyembroidery's commands by the writer).
STITCH, JUMP, TRIM = 0, 1, 2

# Style name -> options class; the generator for each class is in _GENERATORS.
STYLES: dict[str, type] = {
    "running": RunningOptions,
    "triple": TripleOptions,
    "zigzag": ZigzagOptions,
    "arrows": ArrowOptions,
}

_GENERATORS: dict[type, Callable[[Stroke, object, float], NeedlePoints]] = {
    RunningOptions: lambda stroke, o, offset: running_stitch(stroke, o),
    TripleOptions: lambda stroke, o, offset: triple_stitch(stroke, o),
    ZigzagOptions: lambda stroke, o, offset: zigzag_stitch(stroke, o),
    ArrowOptions: lambda stroke, o, offset: arrow_stitch(stroke, o, offset=offset),
}

# Needle points the min-stitch rule may drop: body points, never tacks or locks.
_DROPPABLE = np.zeros(8, dtype=bool)
_DROPPABLE[[BODY, UNDERLAY, MOTIF, TRAVEL]] = True


def style_options(name: str, **values) -> StyleOptions:
    """Options of the style `name` ('running', 'triple', 'zigzag', 'arrows'); `values` that
    are None are left at the style's default."""
    cls = STYLES.get(str(name).lower())
    if cls is None:
        raise InputError(f"unknown stitch style {name!r}; use one of {', '.join(STYLES)}")
    fields = cls.__dataclass_fields__
    return cls(**{k: v for k, v in values.items() if v is not None and k in fields})


def style_reach(style: StyleOptions) -> float:
    """How far needle points may stray from the curve, mm (for hoop checks)."""
    if isinstance(style, ZigzagOptions):
        return style.reach
    if isinstance(style, ArrowOptions):
        return style.width / 2.0
    return 0.0


@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """style: options of one stitch style; lock: tack and lock form; min_stitch: shortest
    stitch outside locks, mm; max_stitch: longest needle-down move per axis, mm;
    trim_distance: strokes further apart are trimmed and jumped, mm; color: thread RGB;
    grid: the files' coordinate step, mm."""

    style: StyleOptions = field(default_factory=RunningOptions)
    lock: LockOptions = field(default_factory=LockOptions)
    min_stitch: float = 0.3
    max_stitch: float = 12.1
    trim_distance: float = 3.0
    color: tuple[int, int, int] = (0, 0, 0)
    grid: float = 0.1

    def __post_init__(self) -> None:
        if type(self.style) not in _GENERATORS:
            raise InputError(f"unknown stitch style options {type(self.style).__name__}")
        if not self.min_stitch >= self.grid:
            raise InputError(f"minimum stitch {self.min_stitch:g} mm must be at least {self.grid:g} mm")
        if not self.max_stitch >= 1.0:
            raise InputError(f"maximum stitch {self.max_stitch:g} mm must be at least 1 mm")
        if not self.max_stitch > 2 * self.min_stitch:
            raise InputError(f"maximum stitch {self.max_stitch:g} mm must exceed twice the minimum "
                             f"{self.min_stitch:g} mm")
        if not self.trim_distance >= 0:
            raise InputError(f"trim distance {self.trim_distance:g} mm must be >= 0")
        if len(self.color) != 3 or not all(0 <= int(c) <= 255 for c in self.color):
            raise InputError(f"thread colour {self.color!r} must be three values 0-255")


@dataclass(frozen=True, eq=False)
class StitchPlan:
    """Rows in sewing order. points (N, 2) mm on the 0.1 mm grid; kinds (N,) STITCH (needle
    down here), JUMP (move here needle up) or TRIM (cut at the current point); roles (N,)
    needle roles (BODY, TACK, LOCK, ...); params (N,): stroke index + curve parameter t
    (NaN on jumps and trims); strokes (N,): index of the drawing's stroke each row sews
    (-1 on trims and jumps); color: thread RGB; skipped: strokes too short to sew."""

    points: np.ndarray
    kinds: np.ndarray
    roles: np.ndarray
    params: np.ndarray
    strokes: np.ndarray
    color: tuple[int, int, int] = (0, 0, 0)
    skipped: int = 0

    def __len__(self) -> int:
        return len(self.points)

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
        pts = self.points[self.kinds != TRIM]
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


def _assemble(drawing: Drawing, options: PlanOptions):
    """Rows before cleanup: float points, kinds, roles, params; and the skipped count."""
    generate = _GENERATORS[type(options.style)]
    pts, kinds, roles, params, owners = [], [], [], [], []
    current: np.ndarray | None = None
    offset, skipped = 0.0, 0

    def add(p, kind, role, param, owner):
        p = np.atleast_2d(p)
        owners.append(np.full(len(p), owner, dtype=np.int64))
        pts.append(p)
        kinds.append(np.full(len(p), kind, dtype=np.uint8))
        roles.append(np.broadcast_to(np.asarray(role, dtype=np.uint8), (len(p),)))
        params.append(np.broadcast_to(np.asarray(param, dtype=float), (len(p),)))

    for index, stroke in enumerate(drawing.strokes):
        length = stroke.length
        if length < options.min_stitch:
            skipped += 1
            offset += length
            continue
        body = generate(stroke, options.style, offset)
        offset += length
        path = body.points
        connect = TACK
        if current is not None:
            if np.linalg.norm(path[0] - current) > options.trim_distance:
                add(current, TRIM, TRAVEL, np.nan, -1)
                add(path[0], JUMP, TRAVEL, np.nan, -1)
            else:
                connect = TRAVEL  # a short stitch from the last stroke's end
        head, tail = _lock_paths(body)
        add(tack_points(head, options.lock), STITCH, [connect, TACK, TACK, TACK], index + body.t[0], index)
        body_roles = body.roles.copy()
        body_roles[0] = TACK  # the stitch into the start closes the tack
        add(path, STITCH, body_roles, index + body.t, index)
        add(lock_points(tail, options.lock), STITCH, LOCK, index + body.t[-1], index)
        current = path[-1]
    if not pts:
        raise InputError("no stroke is long enough to stitch "
                         f"(all shorter than the minimum stitch {options.min_stitch:g} mm)")
    return (np.concatenate(pts), np.concatenate(kinds), np.concatenate(roles),
            np.concatenate(params), np.concatenate(owners), skipped)


def _merge_short(units: np.ndarray, kinds: np.ndarray, roles: np.ndarray, min_units: float) -> np.ndarray:
    """Keep-mask: drop zero-length stitches anywhere and body stitches shorter than
    `min_units` (grid units). When the short stitch ends a body (the lock's anchor), the
    body point before it goes instead. Only short places are visited one by one."""
    n = len(units)
    keep = np.ones(n, dtype=bool)
    sewn = np.zeros(n, dtype=bool)
    sewn[1:] = (kinds[1:] == STITCH) & (kinds[:-1] == STITCH)
    d = np.full(n, np.inf)
    d[1:] = np.hypot(*(units[1:] - units[:-1]).T)
    work = np.flatnonzero(sewn & ((d == 0) | ((d < min_units) & _DROPPABLE[roles]))).tolist()
    heapq.heapify(work)

    def previous_kept(i: int) -> int:
        k = i - 1
        while not keep[k]:
            k -= 1
        return k

    while work:
        i = heapq.heappop(work)
        k = previous_kept(i)
        if not keep[i] or kinds[k] != STITCH or kinds[i] != STITCH:
            continue
        dist = float(np.hypot(*(units[i] - units[k])))
        if dist == 0:
            keep[i] = False
        elif dist < min_units and _DROPPABLE[roles[i]]:
            anchor = i + 1 < n and roles[i + 1] == LOCK and kinds[i + 1] == STITCH
            if not anchor:
                keep[i] = False
            elif _DROPPABLE[roles[k]] and kinds[k - 1] == STITCH:
                keep[k] = False  # the lock's anchor stays; the body point before it goes
                heapq.heappush(work, i)
                continue
            else:
                # The body shrank to one short stitch: drop its end, the lock stands in.
                keep[i] = False
        else:
            continue
        if i + 1 < n:
            heapq.heappush(work, i + 1)  # the next stitch now starts further back
    return keep


def _split_long(units, kinds, roles, params, owners, max_units: int):
    """Split needle-down moves longer than `max_units` per axis into real stitches, on the grid."""
    sewn = np.zeros(len(units), dtype=bool)
    sewn[1:] = (kinds[1:] == STITCH) & (kinds[:-1] == STITCH)
    step = np.zeros(len(units), dtype=np.int64)
    step[1:] = np.abs(np.diff(units, axis=0)).max(axis=1)
    pieces = np.where(sewn, -(-step // max_units), 1)
    pieces = np.maximum(pieces, 1)
    if pieces.max() == 1:
        return units, kinds, roles, params, owners
    # Row i becomes pieces[i] rows: intermediate points on the way from row i - 1.
    owner = np.repeat(np.arange(len(units)), pieces)
    k = np.arange(owner.size) - np.repeat(np.cumsum(pieces) - pieces, pieces) + 1
    frac = k / pieces[owner]
    prev = units[np.maximum(owner - 1, 0)]
    # floor(k * d / n) steps differ by at most ceil(d / n) <= max_units per axis.
    new_units = prev + np.floor((units[owner] - prev) * frac[:, None] + 0.5).astype(np.int64)
    prev_param = params[np.maximum(owner - 1, 0)]
    new_params = prev_param + (params[owner] - prev_param) * frac
    return new_units, kinds[owner], roles[owner], new_params, owners[owner]


def plan_embroidery(drawing: Drawing, options: PlanOptions = PlanOptions()) -> StitchPlan:
    """Stitch every stroke of `drawing` (mm, centred on (0, 0)) into one `StitchPlan`."""
    if drawing.unit != "mm":
        raise InputError(f"place the drawing in mm before stitching (it is in {drawing.unit})")
    if not drawing.strokes:
        raise InputError("the drawing has no strokes to stitch")
    points, kinds, roles, params, owners, skipped = _assemble(drawing, options)
    units = np.rint(points / options.grid).astype(np.int64)
    keep = _merge_short(units, kinds, roles, options.min_stitch / options.grid - 1e-9)
    units, kinds, roles, params, owners = units[keep], kinds[keep], roles[keep], params[keep], owners[keep]
    max_units = int(np.floor(options.max_stitch / options.grid + 1e-9))
    units, kinds, roles, params, owners = _split_long(units, kinds, roles, params, owners, max_units)
    if not np.any(kinds == STITCH):
        raise FabricationError("no needle points left after merging short stitches")
    return StitchPlan(points=units * options.grid, kinds=kinds, roles=roles, params=params,
                      strokes=owners, color=tuple(int(c) for c in options.color), skipped=skipped)
