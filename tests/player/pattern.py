"""Real files for the player tests: a two-colour embroidery pattern with trims and jumps
(written by pyembroidery), and the page's embedded data decoded back."""

from __future__ import annotations

import json
import re

import pyembroidery

from fabrication.player.data import decode_array

RED, BLUE = (200, 30, 40), (30, 80, 200)


def two_colour_pattern() -> pyembroidery.EmbPattern:
    """40 red zigzag stitches, a trim, a jump, 30 more red, a colour change, 50 blue (0.1 mm units)."""
    pattern = pyembroidery.EmbPattern()
    for rgb in (RED, BLUE):
        pattern.add_thread({"color": (rgb[0] << 16) | (rgb[1] << 8) | rgb[2]})
    for i in range(40):
        pattern.add_stitch_absolute(pyembroidery.STITCH, i * 20, (i % 2) * 30)
    pattern.add_stitch_absolute(pyembroidery.TRIM, 780, 30)
    pattern.add_stitch_absolute(pyembroidery.JUMP, 0, 300)
    for i in range(30):
        pattern.add_stitch_absolute(pyembroidery.STITCH, i * 20, 300 + (i % 2) * 30)
    pattern.add_stitch_absolute(pyembroidery.COLOR_CHANGE, 580, 330)
    pattern.add_stitch_absolute(pyembroidery.JUMP, 0, 600)
    for i in range(50):
        pattern.add_stitch_absolute(pyembroidery.STITCH, i * 20, 600 + (i % 3) * 20)
    pattern.add_stitch_absolute(pyembroidery.END, 0, 0)
    return pattern


def write_pattern(path) -> None:
    pyembroidery.write(two_colour_pattern(), str(path), {"trims": True})


def page_data(html: str) -> dict:
    """The JSON the page embeds, with its typed arrays decoded to numpy."""
    match = re.search(r'<script type="application/json" id="player-data">(.*?)</script>', html, re.S)
    assert match, "the page embeds no player data"
    data = json.loads(match.group(1))
    for key, dtype in (("x", "<f4"), ("y", "<f4"), ("t", "<f8"), ("kind", "u1"), ("color", "<u2"),
                       ("num", "<u4")):
        data[key] = decode_array(data[key], dtype)
    return data
