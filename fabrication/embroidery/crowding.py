"""Needle points of a column stroke (satin or zigzag) held within the density limit.

Where a column's needle points crowd more than `quality.DENSITY_LIMIT` within
`quality.DENSITY_RADIUS` (the inside of a tight bend, a narrow column's centre walk, two
columns meeting at a corner), the points there are relieved, cheapest first:

1. underlay points are left out (the walk then takes one longer stitch, at most
   `max_gap` mm, which the top stitches cover);
2. top points are inset towards the row's centre (Ink/Stitch's short stitches made deeper),
   an eighth, a quarter, a half... of their room, to where no point around exceeds the limit and the
   needle stays clear of its last and next holes on that side, and no ground it leaves
   bare opens a slit (a gap between top stitches wider than the spacing, judged on the
   files' 0.1 mm grid: wider than the spacing plus one grid step);
3. where the line comes back over a place (a crossing, a closed line's ends), top points of
   the first pass there, which the later pass covers, are left out while the stitch that
   replaces their two stays within `max_top_gap` mm and no slit opens.

What cannot be relieved so is left to the stats' warning, which names the place. Only
the neighbourhoods of dense points are visited (a tree query finds them), so a stroke
with none costs one density count.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from fabrication.embroidery.needles import BODY, GRID, SNAP_ALLOWANCE, UNDERLAY
from fabrication.embroidery.quality import DENSITY_LIMIT, DENSITY_RADIUS, HOLE_GAP, HOLE_WINDOW

# A point with another within the radius sewn more than this many needle points later
# lies where the line comes back (a crossing, a closed line's ends).
AGAIN = 12
# Inset steps tried, as shares of a point's room towards its row's centre.
STEPS = (0.125, 0.25, 0.5, 0.75, 1.0)
# An inset needle keeps this far (mm) from the holes around it on its side of the line;
# one closer than REENTER to a recent hole re-enters it (once snapped to the grid).
CLEAR = HOLE_GAP + 2.0 * SNAP_ALLOWANCE
REENTER = HOLE_GAP + SNAP_ALLOWANCE
# Places (mm apart) probed along the stitches a moved or left-out top point takes away.
PROBE = 0.05


def relieve_crowding(points: np.ndarray, roles: np.ndarray, inward: np.ndarray, sides, *,
                     max_gap: float, max_top_gap: float = 0.0, spacing: float | None = None,
                     limit: int = DENSITY_LIMIT, radius: float = DENSITY_RADIUS) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, 2) mm, keep (N,) bool) with the crowding relieved (module doc).

    points (N, 2) mm in sewing order; roles (N,) (UNDERLAY points may be left out: not the
    first or last point, and only while the stitch that replaces their two stays within
    `max_gap` mm; BODY points only as step 3 says, within `max_top_gap` mm); inward (N, 2)
    mm: how far each point may move towards its row's centre (zeros: it stays); spacing:
    the top stitches' spacing, peak to peak mm, the widest gap a top point moved or left
    out may open (None: not checked); sides: (rows (M,), points (M, 2)) -> (M,) the side of
    the line each is on (+1 / -1, 0 on the line: `quality.stroke_sides`), for the clearance
    from its last and next holes on that side.

    Last, a needle that re-enters one of the last HOLE_WINDOW holes on its side (the
    repeated holes of `quality`) is inset where that clears it, or the underlay holes it
    re-enters are left out, or it is left out (a top point only where no slit opens).
    """
    points = np.asarray(points, dtype=float).copy()
    keep = np.ones(len(points), dtype=bool)
    if not len(points):
        return points, keep
    side = _Sides(points, sides)
    bares = _Bareness(points, keep, roles, inward, None if spacing is None else (spacing + GRID) / 2.0)
    _relieve_density(points, keep, roles, inward, side, sides, max_gap, max_top_gap, bares, limit, radius)
    _clear_holes(points, keep, roles, inward, side, sides, max_gap, bares)
    return points, keep


class _Sides:
    """The side of the line of each point, found when first asked (most never are)."""

    UNKNOWN = 9

    def __init__(self, points: np.ndarray, sides) -> None:
        self.points, self.sides = points, sides
        self.known = np.full(len(points), self.UNKNOWN, dtype=int)

    def __getitem__(self, rows):
        wanted = np.atleast_1d(rows)
        ask = np.unique(wanted[self.known[wanted] == self.UNKNOWN])
        if len(ask):
            self.known[ask] = np.asarray(self.sides(ask, self.points[ask]), dtype=int)
        return self.known[rows]

    def __setitem__(self, row: int, value: int) -> None:
        self.known[row] = value


def straight_density(spacing: float, width: float, radius: float = DENSITY_RADIUS) -> int:
    """Needle points within `radius` mm of a rail point of a straight column `width` mm
    wide sewn at `spacing` mm peak to peak (the same rail every `spacing`, the other rail
    half a spacing along): what the asked spacing itself makes, before any bend. Where it
    passes the limit, the spacing asked is too dense and is warned about, not relieved."""
    k = np.arange(-int(radius / max(spacing, 1e-9)) - 1, int(radius / max(spacing, 1e-9)) + 2)
    same = np.abs(k * spacing) <= radius + 1e-9
    other = np.hypot((k + 0.5) * spacing, width) <= radius + 1e-9
    return int(same.sum() + other.sum())


def _relieve_density(points, keep, roles, inward, side, sides, max_gap, max_top_gap, bares, limit, reach) -> None:
    """In place: steps 1 to 3 of the module doc. Points are counted where they will be
    written: snapped to the files' grid (the plan snaps them so, in this frame)."""
    grid = _snapped(points)
    # The limit + 1 nearest tell whether a point is dense (as `quality.needle_density`).
    tree = cKDTree(grid, balanced_tree=False, compact_nodes=False)
    k = min(limit + 1, len(points))
    distance, _ = tree.query(grid, k=k, distance_upper_bound=reach + 1e-9)
    dense = np.flatnonzero(np.isfinite(distance.reshape(len(points), -1)).sum(axis=1) > limit)
    if not len(dense):
        return
    # The points that may change: within one radius of a dense point; their neighbours
    # (within another radius) are counted with them.
    movable = np.unique(np.concatenate(tree.query_ball_point(grid[dense], reach + 1e-9)))
    local = np.unique(np.concatenate(tree.query_ball_point(grid[movable], 2.0 * reach + 1e-9)))
    pts = grid[local]
    alive = np.ones(len(local), dtype=bool)
    near = _within(pts, pts, reach)
    count = near.sum(axis=1)
    can_move = np.isin(local, movable)
    underlay = (roles[local] == UNDERLAY) & can_move & _droppable(roles, local, len(points))

    def over() -> np.ndarray:
        return alive & (count > limit)

    def leave_out(candidates: np.ndarray, gap: float) -> None:
        """Leave out `candidates` (a mask over `local`, cleared as tried), the most crowding
        first, while a point around them is over the limit and the stitch that replaces
        their two stays within `gap` mm."""
        nonlocal count
        while True:
            o = over()
            if not o.any():
                return
            crowding = (near & o[None, :]).sum(axis=1) * (candidates & alive)
            choice = int(np.argmax(crowding))
            if crowding[choice] == 0:
                return
            candidates[choice] = False
            if not _gap_ok(points, keep, int(local[choice]), roles, gap) or bares(int(local[choice]), None):
                continue  # it would leave too long a stitch, or bare ground: try the others
            alive[choice] = False
            keep[local[choice]] = False
            count = count - near[:, choice]
            near[choice, :] = False
            near[:, choice] = False

    # 1. underlay points, the most crowded first, while one of their neighbours is over.
    leave_out(underlay, max_gap)

    # 2. top points inset towards their row's centre.
    tried = np.zeros(len(local), dtype=bool)
    while True:
        o = over()
        if not o.any():
            break
        pull = (near & o[None, :]).sum(axis=1) * (alive & can_move & ~tried)
        pull *= np.linalg.norm(inward[local], axis=1) > 1e-9
        choice = int(np.argmax(pull))
        if pull[choice] == 0:
            break
        tried[choice] = True
        g = int(local[choice])
        before = int(np.sum(np.maximum(count[alive] - limit, 0)))
        for share in STEPS:
            q = points[g] + inward[g] * share
            q_side = int(sides(np.array([g]), q[None, :])[0])
            if not _clear(points, keep, side, g, q, q_side) or bares(g, q):
                continue
            new_near = _within(_snapped(q[None, :]), pts, reach)[0] & alive
            new_near[choice] = True
            new_count = count - near[choice].astype(int) + new_near.astype(int)
            new_count[choice] = int(new_near.sum())
            excess = int(np.sum(np.maximum(new_count[alive] - limit, 0)))
            if excess < before and not np.any(alive & (new_count > limit) & ~o):
                points[g] = q
                side[g] = q_side
                pts[choice] = _snapped(q[None, :])[0]
                count = new_count
                near[choice, :] = new_near
                near[:, choice] = new_near
                break

    # 3. where the line comes back over itself (a crossing, a closed line's ends), the
    # first pass's top points there, which the later pass covers, are left out.
    later = np.array([np.any(local[near[i]] > local[i] + AGAIN) for i in range(len(local))])
    leave_out((roles[local] == BODY) & (local > 0) & (local < len(points) - 1) & later, max_top_gap)


class _Bareness:
    """Whether moving or leaving out a top point bares the ground: whether a place on the
    top stitches it takes away (the lines to and from it, between consecutive kept BODY
    points) then lies farther than `cover` mm from every top stitch left, so that the
    threads around it no longer meet (a slit). A tree of the points where they first were
    finds the stitches that can pass near (built when first asked)."""

    def __init__(self, points, keep, roles, inward, cover) -> None:
        self.points, self.keep, self.roles, self.inward, self.cover = points, keep, roles, inward, cover
        self.tree = None

    def _neighbour(self, i: int, step: int, skip: int) -> int | None:
        """The kept point before (step -1) or after (+1) `i`, passing over `skip`; None at
        the ends."""
        j = i + step
        while 0 <= j < len(self.points) and (not self.keep[j] or j == skip):
            j += step
        return j if 0 <= j < len(self.points) else None

    def __call__(self, g: int, q: np.ndarray | None) -> bool:
        """Whether moving point `g` to `q` (None: leaving it out) bares the ground."""
        if self.cover is None or self.roles[g] != BODY:
            return False
        points, keep, roles = self.points, self.keep, self.roles
        if self.tree is None:
            top = roles == BODY
            pair = top[:-1] & top[1:]
            longest = float(np.linalg.norm(np.diff(points, axis=0)[pair], axis=1).max(initial=0.0))
            # a stitch passing within `cover` of a place has an end this close to where it was
            self.search = longest / 2.0 + self.cover + 2.0 * float(np.linalg.norm(self.inward, axis=1).max(initial=0.0))
            self.tree = cKDTree(points.copy())
        p = points[g].copy()
        taken = [points[j] for j in (self._neighbour(g, -1, g), self._neighbour(g, 1, g))
                 if j is not None and roles[j] == BODY]
        if not taken:
            return False
        probes = np.concatenate([end + (p - end) * np.linspace(0.0, 1.0, int(np.ceil(np.hypot(*(p - end)) / PROBE)) + 1)
                                 [:, None] for end in taken])
        near = set()
        for found in self.tree.query_ball_point(probes[::4], self.search + 4 * PROBE):  # every fourth probe's
            near.update(found)
        skip = g if q is None else -1
        stitches = set()
        for i in near:
            if not keep[i] or roles[i] != BODY or i == skip:
                continue
            for step in (-1, 1):  # the stitches at i: to its kept neighbours
                j = self._neighbour(i, step, skip)
                if j is not None and roles[j] == BODY:
                    stitches.add((min(i, j), max(i, j)))
        if not stitches:
            return True
        pairs = np.array(sorted(stitches))
        a, b = points[pairs[:, 0]].copy(), points[pairs[:, 1]].copy()
        if q is not None:
            a[pairs[:, 0] == g], b[pairs[:, 1] == g] = q, q
        ab = b - a
        u = np.einsum("pkj,kj->pk", probes[:, None, :] - a[None], ab) / np.maximum(np.einsum("kj,kj->k", ab, ab), 1e-12)
        foot = a[None] + np.clip(u, 0.0, 1.0)[..., None] * ab[None]
        return bool(np.linalg.norm(probes[:, None, :] - foot, axis=2).min(axis=1).max() > self.cover + 1e-9)


def _clear_holes(points, keep, roles, inward, side, sides, max_gap, bares) -> None:
    """In place: needles within HOLE_GAP (and a snap) of one of the last HOLE_WINDOW kept
    ones on their side are inset clear of them, or the underlay holes they re-enter (under
    the top) are left out, or they are left out themselves; a top point only where that
    bares no ground (module doc)."""
    n = len(points)
    for row in _reentering(points, keep, side).tolist():
        if not keep[row] or roles[row] not in (BODY, UNDERLAY) or row in (0, n - 1) or \
                _clear(points, keep, side, row, points[row], int(side[row]), ahead=False, gap=REENTER):
            continue
        for share in STEPS if np.linalg.norm(inward[row]) > 1e-9 else ():
            q = points[row] + inward[row] * share
            q_side = int(sides(np.array([row]), q[None, :])[0])
            if _clear(points, keep, side, row, q, q_side) and not bares(row, q):
                points[row], side[row] = q, q_side
                break
        else:
            if _leave_out_holes(points, keep, roles, side, row, max_gap):
                continue
            if (roles[row] == BODY and not bares(row, None)) or \
                    (roles[row] == UNDERLAY and _gap_ok(points, keep, row, roles, max_gap)):
                keep[row] = False


def _leave_out_holes(points, keep, roles, side, row: int, max_gap: float) -> bool:
    """Leave out the holes `row` re-enters (the kept needle points among the last
    HOLE_WINDOW on its side within REENTER mm) when all are underlay points that may go
    (`_gap_ok`); whether it did."""
    holes, k = [], row - 1
    seen = 0
    while k >= 0 and seen < HOLE_WINDOW:
        if keep[k]:
            seen += 1
            if side[k] == side[row] and np.hypot(*(points[k] - points[row])) < REENTER:
                holes.append(k)
        k -= 1
    if not holes or any(roles[h] != UNDERLAY or h == 0 for h in holes):
        return False
    for k, h in enumerate(holes):
        if not _gap_ok(points, keep, h, roles, max_gap):
            keep[holes[:k]] = True
            return False
        keep[h] = False
    return True


def _reentering(points: np.ndarray, keep: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Rows whose needle comes within REENTER mm of one of the HOLE_WINDOW kept needle
    points before it on its side; ascending."""
    rows = np.flatnonzero(keep)
    p = points[rows]
    found = []
    for lag in range(1, HOLE_WINDOW + 1):
        close = np.flatnonzero(np.linalg.norm(p[lag:] - p[:-lag], axis=1) < REENTER)
        if len(close):
            later, earlier = rows[close + lag], rows[close]
            found.append(later[side[later] == side[earlier]])
    return np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=np.int64)


def _snapped(points: np.ndarray) -> np.ndarray:
    """`points` (N, 2) mm on the files' GRID, as the planner writes them."""
    return np.rint(points / GRID) * GRID


def _within(a: np.ndarray, b: np.ndarray, reach: float) -> np.ndarray:
    """(len(a), len(b)) True where a point of `a` lies within `reach` mm of one of `b`."""
    d = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return d <= reach + 1e-9


def _droppable(roles: np.ndarray, rows: np.ndarray, n: int) -> np.ndarray:
    """(len(rows),) True for underlay rows other than the stroke's first and last point."""
    return (roles[rows] == UNDERLAY) & (rows > 0) & (rows < n - 1)


def _gap_ok(points: np.ndarray, keep: np.ndarray, row: int, roles: np.ndarray, max_gap: float) -> bool:
    """Whether leaving out underlay `row` keeps the stitch between the kept points before
    and after it within `max_gap` mm."""
    lo = row - 1
    while lo > 0 and not keep[lo]:
        lo -= 1
    hi = row + 1
    while hi < len(points) - 1 and not keep[hi]:
        hi += 1
    if not (keep[lo] and keep[hi]):
        return False
    return float(np.hypot(*(points[hi] - points[lo]))) <= max_gap


def _clear(points: np.ndarray, keep: np.ndarray, side: np.ndarray, row: int, q: np.ndarray, q_side: int, *,
           ahead: bool = True, gap: float = 0.0) -> bool:
    """Whether a needle at `q` (on side `q_side`) for `row` keeps `gap` (CLEAR when 0) mm
    from the last and (`ahead`) next HOLE_WINDOW kept needle points on its side of the line."""
    others = []
    k = row - 1
    while k >= 0 and len(others) < HOLE_WINDOW:
        if keep[k]:
            others.append(k)
        k -= 1
    k, later = row + 1, 0
    while ahead and k < len(points) and later < HOLE_WINDOW:
        if keep[k]:
            others.append(k)
            later += 1
        k += 1
    others = [k for k in others if side[k] == q_side]
    if not others:
        return True
    return bool(np.min(np.linalg.norm(points[others] - q, axis=1)) >= (gap or CLEAR))
