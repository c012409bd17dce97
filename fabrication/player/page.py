"""The standalone player page: one HTML file with the player's JS, CSS and data inline.

No server and no network: the page opens from disk (file://) in any modern browser.
The studio serves the same `static/player.js` and `static/player.css` and feeds them
`PlayerData.to_json()`; this module only inlines them.
"""

from __future__ import annotations

import html
import os
from importlib import resources
from pathlib import Path

from fabrication.player.data import PlayerData
from onestroke.atomic import atomic_write_text, check_writable
from onestroke.errors import InputError
from onestroke.paths import check_distinct

PAGE_SUFFIXES = (".html", ".htm")


def asset_text(name: str) -> str:
    """Text of a file shipped in `fabrication/player/static/` ('player.js', 'player.css')."""
    return resources.files("fabrication.player").joinpath("static", name).read_text(encoding="utf-8")


def player_html(data: PlayerData) -> str:
    """The whole page as a string: markup, inline CSS, inline JS module, inline JSON data."""
    # '</' would end the inline script early; the JS source never needs it literally
    script = asset_text("player.js").replace("</", "<\\/")
    return "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        # forbid every fetch: the page must work, and be seen to work, offline
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
        "script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:\">",
        f"<title>{html.escape(data.title)} - onestroke player</title>",
        f"<style>\nhtml, body {{ height: 100%; margin: 0; }}\n{asset_text('player.css')}\n</style>",
        "</head>",
        "<body>",
        '<div id="player" class="osp-root"></div>',
        f'<script type="application/json" id="player-data">{data.to_json()}</script>',
        '<script type="module">',
        script,
        'const data = JSON.parse(document.getElementById("player-data").textContent);',
        'window.player = createPlayer(document.getElementById("player"), data);',
        "</script>",
        "</body>",
        "</html>",
        "",
    ])


def write_player_html(data: PlayerData, path: str | os.PathLike, *,
                      source: str | os.PathLike | None = None) -> Path:
    """Write the standalone page for `data` to `path` (.html) atomically and return it.

    source: the input file; the page never overwrites it.
    """
    path = Path(path)
    if path.suffix.lower() not in PAGE_SUFFIXES:
        raise InputError(f"player page {str(path)!r} must end in .html")
    check_distinct(inputs=[("input", source)], outputs=[("output", path)])
    check_writable(path)
    atomic_write_text(path, player_html(data))
    return path
