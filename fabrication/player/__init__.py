"""The toolpath player: stitches, laser moves or a drawing's pen, played in order on a time axis.

`player_data_for_file` (or the per-source builders) makes `PlayerData`; `write_player_html`
writes it as one self-contained page; the studio serves `static/player.js` with the same data.
"""

from fabrication.player.data import PlayerData
from fabrication.player.from_drawing import drawing_player_data
from fabrication.player.from_embroidery import embroidery_file_player_data, stitch_player_data
from fabrication.player.from_file import playable_suffixes, player_data_for_file
from fabrication.player.from_gcode import gcode_file_player_data, gcode_player_data, laser_program_player_data
from fabrication.player.page import asset_text, player_html, write_player_html

__all__ = ["PlayerData", "asset_text", "drawing_player_data", "embroidery_file_player_data",
           "gcode_file_player_data", "gcode_player_data", "laser_program_player_data", "playable_suffixes",
           "player_data_for_file", "player_html", "stitch_player_data", "write_player_html"]
