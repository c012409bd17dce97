"""What the player plays: rows of head moves on a time axis, and their compact JSON.

One row per point the head reaches, in order. Row i is the move from point i-1 to point i
(row 0 starts and ends at point 0), finished at `times[i]`; its kind says what the move
leaves behind. The same data serves embroidery files, G-code and drawings, so one player
(``static/player.js``) shows all three, in the standalone HTML file and in the studio.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass, field

import numpy as np

from onestroke.errors import FabricationError, InputError

# Row kinds (the JS player uses the same numbers).
DRAW = 0      # needle, beam or pen down: a line from the previous point, in the row's colour
TRAVEL = 1    # the head moves without leaving a line (jump, rapid / laser off, pen up)
TRIM = 2      # the thread is cut here (no motion)
COLOR = 3     # colour change here (no motion; later rows use the next thread)
DOWN = 4      # needle down here after travel: a needle point, no sewn line from the previous point
KIND_NAMES = ("draw", "travel", "trim", "color", "down")

FORMAT_VERSION = 1


@dataclass(frozen=True, kw_only=True, eq=False)
class PlayerData:
    """Rows of head moves for the player.

    source: "embroidery", "gcode" or "drawing". title: shown in the header (a file name).
    points (N, 2) float, in `unit` ("mm" or "px"), +y down unless `y_up` (G-code machine
    coordinates). kinds (N,) uint8 row kinds (DRAW, TRAVEL, TRIM, COLOR, DOWN). colors (N,)
    int index into `palette` ('#rrggbb' strings). times (N,) float cumulative
    `time_unit` ("s", or the drawing's unit when the axis is the length drawn) at the end
    of each row, non-decreasing. numbers (N,) int the figure shown for the row
    (`number_label`: stitch number, G-code line, stroke), of `number_total`. total: end of
    the time axis (>= times[-1]). frame: optional (xmin, ymin, xmax, ymax) outline (hoop
    or bed). info: lines of figures shown beside the player. warnings: for the caller.
    """

    source: str
    title: str
    points: np.ndarray
    kinds: np.ndarray
    colors: np.ndarray
    palette: tuple[str, ...]
    times: np.ndarray
    numbers: np.ndarray
    number_label: str
    number_total: int
    total: float
    unit: str = "mm"
    time_unit: str = "s"
    y_up: bool = False
    frame: tuple[float, float, float, float] | None = None
    info: tuple[str, ...] = ()
    warnings: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        n = len(self.points)
        if n == 0:
            raise InputError(f"{self.title!r} holds nothing to play")
        for name in ("kinds", "colors", "times", "numbers"):
            if len(getattr(self, name)) != n:
                raise FabricationError(f"PlayerData.{name} has {len(getattr(self, name))} rows, points {n}")
        if len(self.palette) == 0 or int(np.max(self.colors)) >= len(self.palette):
            raise FabricationError("PlayerData.colors index past the palette")

    def __len__(self) -> int:
        return len(self.points)

    def to_dict(self) -> dict:
        """JSON-ready dict; arrays as base64 little-endian typed arrays (x, y float32,
        t float64, kind uint8, color uint16, num uint32), the layout player.js decodes."""
        return {
            "version": FORMAT_VERSION,
            "source": self.source,
            "title": self.title,
            "n": len(self),
            "unit": self.unit,
            "timeUnit": self.time_unit,
            "yUp": bool(self.y_up),
            "total": float(self.total),
            "numberLabel": self.number_label,
            "numberTotal": int(self.number_total),
            "palette": list(self.palette),
            "frame": None if self.frame is None else [float(v) for v in self.frame],
            "info": list(self.info),
            "x": _b64(self.points[:, 0], "<f4"),
            "y": _b64(self.points[:, 1], "<f4"),
            "t": _b64(self.times, "<f8"),
            "kind": _b64(self.kinds, "u1"),
            "color": _b64(self.colors, "<u2"),
            "num": _b64(self.numbers, "<u4"),
        }

    def to_json(self) -> str:
        """Compact JSON of `to_dict` (safe to embed in a <script> element: no '<')."""
        text = json.dumps(self.to_dict(), separators=(",", ":"), ensure_ascii=True)
        return text.replace("<", "\\u003c")


def decode_array(text: str, dtype: str) -> np.ndarray:
    """Inverse of the base64 encoding in `PlayerData.to_dict` (for tests and tools)."""
    return np.frombuffer(base64.b64decode(text), dtype=dtype)


def hex_color(rgb) -> str:
    """'#rrggbb' of an RGB triple 0-255."""
    r, g, b = (int(v) for v in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def ramp_palette(fraction: np.ndarray, ramp, steps: int = 64) -> tuple[np.ndarray, tuple[str, ...]]:
    """Quantize positions in [0, 1] to `steps` colours of `ramp` (u (M,) -> RGB (M, 3) uint8).

    Returns (indices (N,) int, palette of '#rrggbb'): a few dozen colours draw as few
    canvas paths, and the order still reads as colour.
    """
    index = np.clip(np.rint(np.nan_to_num(fraction) * (steps - 1)), 0, steps - 1).astype(np.int64)
    rgb = ramp(np.linspace(0.0, 1.0, steps))
    return index, tuple(hex_color(c) for c in rgb)


def _b64(values: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype=dtype).tobytes()).decode("ascii")
