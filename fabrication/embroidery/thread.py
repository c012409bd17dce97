"""Thread colours and thread catalogues.

Colours come as '#rrggbb', 'rrggbb', '#rgb' or a CSS colour name. A thread chart is one
of the catalogues pyembroidery ships (Brother, Janome, Husqvarna, Viking, Janome SEW):
`nearest_thread` picks the catalogue thread closest to a colour with pyembroidery's own
red-mean distance, the one its writers use to map colours to machine palettes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache

from PIL import ImageColor
from pyembroidery import EmbThreadHus, EmbThreadJef, EmbThreadPec, EmbThreadSew, EmbThreadShv
from pyembroidery.EmbThread import find_nearest_color_index

from onestroke.errors import InputError

RGB = tuple[int, int, int]

# Chart name -> (brand shown to the user, pyembroidery's catalogue module).
THREAD_CHARTS = {
    "brother": ("Brother", EmbThreadPec),
    "janome": ("Janome", EmbThreadJef),
    "husqvarna": ("Husqvarna", EmbThreadHus),
    "viking": ("Husqvarna Viking", EmbThreadShv),
    "janome-sew": ("Janome SEW", EmbThreadSew),
}
# Catalogues users ask for that pyembroidery does not ship: named in the refusal.
_NOT_SHIPPED = ("madeira", "isacord", "robison-anton", "sulky", "gunold", "floriani")


@dataclass(frozen=True, kw_only=True)
class Thread:
    """One thread: `color` RGB 0-255; `number` / `name` / `chart`: its catalogue entry
    when a thread chart picked it (None otherwise)."""

    color: RGB
    number: str | None = None
    name: str | None = None
    chart: str | None = None

    def __post_init__(self) -> None:
        if len(self.color) != 3 or not all(0 <= int(c) <= 255 for c in self.color):
            raise InputError(f"thread colour {self.color!r} must be three values 0-255")
        object.__setattr__(self, "color", tuple(int(c) for c in self.color))

    @property
    def hex(self) -> str:
        return "#{:02x}{:02x}{:02x}".format(*self.color)

    @property
    def label(self) -> str:
        """'#c81e28' or 'Brother 800 Red (#c81e28 asked)' style text for stats."""
        if self.number is None:
            return self.hex
        return f"{self.chart} {self.number} {self.name} {self.hex}"


def parse_color(text: str) -> RGB:
    """RGB 0-255 of a colour given as '#c81e28', 'c81e28', '#c12' or a name like 'navy'."""
    value = str(text).strip()
    if re.fullmatch(r"[0-9a-fA-F]{6}|[0-9a-fA-F]{3}", value):
        value = "#" + value
    try:
        rgb = ImageColor.getrgb(value)
    except ValueError:
        raise InputError(f"thread colour {text!r} is not a colour; use '#rrggbb' or a name like "
                         "'black', 'navy', 'crimson'") from None
    return int(rgb[0]), int(rgb[1]), int(rgb[2])


def parse_colors(text: str) -> tuple[RGB, ...]:
    """A comma-separated list of colours ('red,#0a0,navy'), in order."""
    parts = [p for p in str(text).split(",") if p.strip()]
    if not parts:
        raise InputError(f"thread colour list {text!r} is empty; use e.g. 'black' or 'red,#00a000,navy'")
    return tuple(parse_color(p) for p in parts)


def check_chart(name: str) -> str:
    """The canonical chart name, or `InputError` naming the charts pyembroidery ships."""
    key = str(name).strip().lower()
    if key in THREAD_CHARTS:
        return key
    shipped = ", ".join(THREAD_CHARTS)
    if key in _NOT_SHIPPED:
        raise InputError(f"thread chart {name!r} is not among the catalogues pyembroidery ships; "
                         f"use one of {shipped}")
    raise InputError(f"unknown thread chart {name!r}; use one of {shipped}")


@lru_cache(maxsize=None)
def _catalogue(chart: str):
    return [t for t in THREAD_CHARTS[chart][1].get_thread_set() if t is not None]


def nearest_thread(color: RGB, chart: str) -> Thread:
    """The thread of `chart` nearest to `color` (pyembroidery's red-mean colour distance)."""
    chart = check_chart(chart)
    threads = _catalogue(chart)
    r, g, b = (int(c) for c in color)
    best = threads[find_nearest_color_index((r << 16) | (g << 8) | b, threads)]
    return Thread(color=(best.get_red(), best.get_green(), best.get_blue()),
                  number=str(best.catalog_number), name=str(best.description),
                  chart=THREAD_CHARTS[chart][0])
