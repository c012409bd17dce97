"""Thread colours: '#rrggbb', 'rrggbb', '#rgb' or a CSS colour name, to RGB."""

from __future__ import annotations

import re

from PIL import ImageColor

from onestroke.errors import InputError


def parse_color(text: str) -> tuple[int, int, int]:
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
