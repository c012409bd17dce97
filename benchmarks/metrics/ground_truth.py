"""Ground truth of one benchmark drawing (shared by the generated sets, the glyph sets and the
handwriting set): the drawing, its crossings, its events and the zones where output
intersections are not counted."""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import chain, islice, zip_longest

import numpy as np

from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

CANVAS = 1000
MARGIN = 30  # px between the ink and the canvas edge


@dataclass(frozen=True)
class Event:
    """A ground-truth place where the line meets (or nearly meets) itself.

    kind: "crossing", "touch", "near-touch", "spike-base", "spike-tip" or "end";
    point: (2,) px; angle: crossing angle in degrees (0 for the others);
    radius: half-extent of the ink-merge zone around the point (px); group: events of one
    feature (a spike's base and tip) share a group.
    """

    kind: str
    point: np.ndarray
    angle: float = 0.0
    radius: float = 0.0
    group: int = -1


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """One benchmark drawing and its ground truth.

    drawing: one stroke, px on a CANVAS x CANVAS canvas, with its stroke_width;
    intersections: (n, 2) crossing points (touches are not intersections);
    dont_care: shapely geometries (touch points, near-touches, retraced parts) near which
    output intersections are not counted either way; events: all designed and found events.
    """

    name: str
    kind: str
    drawing: Drawing
    closed: bool
    intersections: np.ndarray
    events: tuple[Event, ...] = ()
    dont_care: tuple = ()
    meta: dict = field(default_factory=dict)

    @property
    def stroke(self) -> Stroke:
        return self.drawing.strokes[0]

    @property
    def width(self) -> float:
        return self.drawing.stroke_width

    def count(self, kind: str) -> int:
        return sum(1 for e in self.events if e.kind == kind)


class Rejected(Exception):
    """A sample that breaks a rule; the generator draws another."""


_NONE_LEFT = object()


def interleaved(queues, count: int | None = None) -> list:
    """One item of each queue in turn (a queue that runs out is passed over), the first
    `count` (default all): a set mixing its sources so that any first part has each kind."""
    mixed = (item for item in chain.from_iterable(zip_longest(*queues, fillvalue=_NONE_LEFT))
             if item is not _NONE_LEFT)
    return list(islice(mixed, count))
