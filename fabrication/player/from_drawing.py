"""Player rows from a drawing: the pen along each stroke in drawing order.

The time axis is the length drawn (in the drawing's unit), so the pen moves at an even
pace along the curve; the move to the next stroke's start is pen-up travel and takes no
length. Colours run start to end along the same gradient as the drawing preview.
"""

from __future__ import annotations

import numpy as np

from fabrication.embroidery.canvas import gradient
from fabrication.player.data import DRAW, TRAVEL, PlayerData, ramp_palette
from onestroke.errors import InputError
from vectorize.drawing import Drawing


def drawing_player_data(drawing: Drawing, *, title: str = "drawing",
                        tolerance: float | None = None) -> PlayerData:
    """`PlayerData` of `drawing` (its unit, +y down).

    tolerance: chord tolerance for flattening the strokes, in the drawing's unit (None:
    1/2000 of the canvas diagonal, a fraction of a pixel on screen).
    """
    if not drawing.strokes:
        raise InputError(f"drawing {title!r} has no strokes to play")
    if tolerance is None:
        tolerance = float(np.hypot(drawing.width, drawing.height)) / 2000.0
    pieces, steps, kinds, numbers = [], [], [], []
    for index, stroke in enumerate(drawing.strokes):
        points = stroke.flatten(tolerance)
        chord = np.hypot(*np.diff(points, axis=0).T)
        # chords scaled to the curve's own length: the axis ends on the drawing's length
        scale = stroke.length / chord.sum() if chord.sum() > 0 else 0.0
        pieces.append(points)
        steps.append(np.r_[0.0, chord * scale])
        kinds.append(np.r_[TRAVEL, np.full(len(points) - 1, DRAW)])
        numbers.append(np.full(len(points), index + 1))
    points = np.vstack(pieces)
    kinds = np.concatenate(kinds).astype(np.uint8)
    along = np.cumsum(np.concatenate(steps))
    total = float(along[-1])
    colors, palette = ramp_palette(along / total if total > 0 else along, gradient)
    info = (f"{len(drawing.strokes)} stroke(s)",
            f"length {drawing.length:.1f} {drawing.unit}",
            f"canvas {drawing.width:g} x {drawing.height:g} {drawing.unit}")
    return PlayerData(
        source="drawing", title=title, points=points, kinds=kinds, colors=colors, palette=palette,
        times=along, numbers=np.concatenate(numbers), number_label="stroke",
        number_total=len(drawing.strokes), total=total, unit=drawing.unit, time_unit=drawing.unit,
        frame=(0.0, 0.0, float(drawing.width), float(drawing.height)), info=info)
