"""`NeedlePoints`: needle positions in order, with the curve parameter and role of each.

Every stitch generator returns one; the planner joins them into a `StitchPlan`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# What a needle point is for. Tests and the min-stitch rule need to tell locks from body.
BODY, TACK, LOCK, UNDERLAY, TRAVEL, MOTIF = range(6)
ROLE_NAMES = ("body", "tack", "lock", "underlay", "travel", "motif")

# Row kinds of a stitch plan (mapped to pyembroidery's commands by the writer). COLOR:
# change to the next thread here (after the lock and trim of the last block).
STITCH, JUMP, TRIM, COLOR = 0, 1, 2, 3

# The files' coordinate step (pyembroidery's units), mm: no length under it can be sewn;
# and the longest stitch any format stores, mm (DST's records hold 12.1 mm: longer ones are
# split there).
GRID, LONGEST_STITCH = 0.1, 12.7

# Half the diagonal of one 0.1 mm grid cell: how far snapping to pyembroidery's units can
# move a needle point. Generators keep this much of every geometric tolerance in reserve
# so that the guarantees hold for the points actually written.
SNAP_ALLOWANCE = 0.0708


@dataclass(frozen=True, eq=False)
class NeedlePoints:
    """Needle positions `points` (N, 2) in mm, stroke parameter `t` (N,) in [0, 1] (for
    colouring and for measuring against the curve) and `roles` (N,) uint8 (BODY, TACK, ...)."""

    points: np.ndarray
    t: np.ndarray
    roles: np.ndarray

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=float).reshape(-1, 2)
        t = np.asarray(self.t, dtype=float).reshape(-1)
        roles = np.asarray(self.roles, dtype=np.uint8).reshape(-1)
        if not len(points) == len(t) == len(roles):
            raise ValueError(f"points {points.shape}, t {t.shape} and roles {roles.shape} differ in length")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "roles", roles)

    def __len__(self) -> int:
        return len(self.points)

    @classmethod
    def of(cls, points: np.ndarray, t: np.ndarray, role: int) -> "NeedlePoints":
        """All points with the same role."""
        return cls(points, t, np.full(len(t), role, dtype=np.uint8))

    @classmethod
    def concat(cls, parts: "list[NeedlePoints]") -> "NeedlePoints":
        parts = [p for p in parts if len(p)]
        if not parts:
            return cls(np.zeros((0, 2)), np.zeros(0), np.zeros(0, dtype=np.uint8))
        return cls(np.concatenate([p.points for p in parts]), np.concatenate([p.t for p in parts]),
                   np.concatenate([p.roles for p in parts]))

    def take(self, index: np.ndarray) -> "NeedlePoints":
        """The points at `index` (any integer array or mask), in that order."""
        return NeedlePoints(self.points[index], self.t[index], self.roles[index])
