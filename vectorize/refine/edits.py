"""A user's corrections to a vectorization (paper 4.3), as plain data that survives a file.

The studio page makes them and `onestroke vectorize --edits FILE` replays them. Every edit
names its place by position (x, y in the output frame: the input image's pixels), not by
an internal node id: the nearest junction or branch within `tolerance` px is meant, so an
edits file still applies after small changes to the algorithm. An edit that matches
nothing is reported as a warning, never an error.

Kinds, and the stage each one re-runs from:
- settings `threshold`, `blur`, `multi`: from binarization;
- `split` (a degree-4 node back into its two degree-3 halves), `merge` (two degree-3 nodes
  joined by the branch at the position): from simplification;
- `pairing` (how the pen went through a degree-4 node: "crossing", "touching" = the
  smoother touching pairing, "third" = the other one): from traversal, as a fixed decision;
- `passes` (how the pen went through a node where three passes meet, six branches: each
  pass as the directions of its two branches leaving the node, degrees, 0 = +x, 90 = +y
  down the image): from traversal, as a fixed decision;
- `reverse` (the stroke through the position runs the other way): after fitting;
  `start` (the stroke with an end at the position starts there, and comes first; in
  single-line mode a free end the line passes, the tip of a stroke drawn out and back,
  becomes an end of the route, which then retraces other branches): from traversal;
- `twice` / `once` (single-line mode: the branch at the position is, or is not, where the
  line goes back over itself when it must retrace something: route inspection then
  prefers, or avoids, retracing it): from traversal;
- `unbridge` (single-line mode: the pen gap that gap bridging joined at the position, its
  middle, stays open: its two sides are separate strokes): from gap bridging. When the ink
  then falls into pieces, single-line mode keeps the largest, as it does for any drawing
  of several pieces, and says so in a warning; multi-stroke mode bridges no gap, so there
  the edit has nothing to do and is not reported as unmatched.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.options import BLUR, THRESHOLD

FORMAT = "onestroke-edits"
PAIRINGS = ("crossing", "touching", "third")
KINDS = ("pairing", "passes", "split", "merge", "reverse", "start", "twice", "once", "unbridge")
# Default match radius in output px: a click lands within a few pixels of a marker.
TOLERANCE = 8.0
MATCH_RADIUS = Range(0.0, None, unit="px", name="edit tolerance", low_open=True)


@dataclass(frozen=True, kw_only=True)
class Edit:
    """One correction at position `at` = (x, y) px of the input image.

    kind: one of KINDS; pairing: for kind "pairing", one of PAIRINGS; passes: for kind
    "passes", the passes through the node as pairs of branch directions (degrees).
    """

    kind: str
    at: tuple[float, float]
    pairing: str | None = None
    passes: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"unknown edit kind {self.kind!r}; use one of {', '.join(KINDS)}")
        try:
            x, y = (float(v) for v in self.at)
        except (TypeError, ValueError):
            raise InputError(f"edit position {self.at!r} must be two numbers (x, y)") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(f"edit position {self.at!r} must be finite")
        object.__setattr__(self, "at", (x, y))
        if self.kind == "pairing":
            if self.pairing not in PAIRINGS:
                raise InputError(f"pairing {self.pairing!r} must be one of {', '.join(PAIRINGS)}")
        elif self.pairing is not None:
            raise InputError(f"a {self.kind!r} edit takes no pairing")
        if self.kind == "passes":
            object.__setattr__(self, "passes", _passes(self.passes))
        elif self.passes is not None:
            raise InputError(f"a {self.kind!r} edit takes no passes")

    def to_dict(self) -> dict:
        data = {"kind": self.kind, "at": [round(self.at[0], 3), round(self.at[1], 3)]}
        if self.pairing is not None:
            data["pairing"] = self.pairing
        if self.passes is not None:
            data["passes"] = [[round(a, 1), round(b, 1)] for a, b in self.passes]
        return data


def _passes(value) -> tuple[tuple[float, float], ...]:
    """Pairs of directions in degrees [0, 360), at least three pairs (six branches)."""
    try:
        pairs = tuple((float(a) % 360.0, float(b) % 360.0) for a, b in value)
    except (TypeError, ValueError):
        raise InputError(f"passes {value!r} must be pairs of directions in degrees, e.g. [[10, 190], ...]") from None
    if len(pairs) < 3 or not all(math.isfinite(a) and math.isfinite(b) for a, b in pairs):
        raise InputError(f"passes {value!r} must be three or more pairs of finite directions in degrees")
    return pairs


@dataclass(frozen=True, kw_only=True)
class Edits:
    """Settings that override the vectorizer's options (None: keep the option) and the
    ordered list of corrections; `tolerance` is the match radius in output px."""

    threshold: float | None = ranged(None, THRESHOLD)
    blur: float | None = ranged(None, BLUR)
    multi: bool | None = None
    tolerance: float = ranged(TOLERANCE, MATCH_RADIUS)
    items: tuple[Edit, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        object.__setattr__(self, "items", tuple(self.items))
        check_ranges(self)

    def of(self, *kinds: str) -> tuple[Edit, ...]:
        """The corrections of these kinds, in order."""
        return tuple(e for e in self.items if e.kind in kinds)

    def applied_to(self, options):
        """`options` (VectorizeOptions) with this file's threshold, blur and mode."""
        changes = {name: getattr(self, name) for name in ("blur", "multi") if getattr(self, name) is not None}
        if self.threshold is not None:
            changes["threshold"] = self.threshold
        return replace(options, **changes) if changes else options

    def to_dict(self) -> dict:
        return {"format": FORMAT, "version": 1, "threshold": self.threshold, "blur": self.blur,
                "multi": self.multi, "tolerance": self.tolerance,
                "edits": [e.to_dict() for e in self.items]}

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1) + "\n"


def _schema() -> dict:
    """What `Edits.to_dict` writes, as `onestroke.json_check` reads it."""
    point = {"type": "array", "minItems": 2, "maxItems": 2, "items": {"type": "number"}}
    # kinds, pairings and the number of passes are checked by `Edit`, whose messages say more
    edit = {"type": "object", "required": ["kind", "at"], "properties": {
        "kind": {"type": "string"}, "at": point, "pairing": {"type": ["string", "null"]},
        "passes": {"type": ["array", "null"], "items": point}}}
    return {"type": "object", "properties": {
        # types here; ranges where `Edits` declares them (one check, the CLI's words)
        "threshold": {"type": ["number", "null"]}, "blur": {"type": ["number", "null"]},
        "multi": {"type": ["boolean", "null"]}, "tolerance": {"type": "number"},
        "edits": {"type": "array", "items": edit}}}


def edits_from_dict(data, *, name: str = "edits") -> Edits:
    """Parse what `Edits.to_dict` made; `InputError` naming `name` (the file) and what in
    it is wrong, checked against the schema before any edit is built."""
    from onestroke.json_check import problem

    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{name}: not an onestroke edits file (expected \"format\": \"{FORMAT}\")")
    if data.get("version") != 1:
        raise InputError(f"{name}: version {data.get('version')!r} is not supported (expected 1)")
    found = problem(data, _schema())
    if found:
        raise InputError(f"{name}: {found}")
    try:
        edits = tuple(Edit(kind=e["kind"], at=tuple(e["at"]), pairing=e.get("pairing"), passes=e.get("passes"))
                      for e in data.get("edits", []))
        multi = data.get("multi")
        return Edits(threshold=_number(data.get("threshold")), blur=_number(data.get("blur")),
                     multi=multi, tolerance=float(data.get("tolerance", TOLERANCE)), items=edits)
    except InputError as error:
        raise InputError(f"{name}: {error}") from None


def _number(value) -> float | None:
    return None if value is None else float(value)


def edits_from_json(text: str | bytes, *, name: str = "edits file") -> Edits:
    """Parse an edits file's text (`name`: the file, for messages)."""
    from onestroke.json_check import parse_json

    return edits_from_dict(parse_json(text, {}, what=name), name=name)  # the schema: after its format


def read_edits(path) -> Edits:
    """Read an edits file (`InputError` when missing, not JSON or not an edits file)."""
    from onestroke.paths import check_input_file

    name = check_input_file(path, what="edits file", expect="an edits .json file")
    with open(name, "rb") as handle:
        return edits_from_json(handle.read(), name=f"edits file {name!r}")
