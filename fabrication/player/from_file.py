"""Player data for any file onestroke reads, chosen by its extension."""

from __future__ import annotations

import os

from fabrication.player.data import PlayerData
from machines.laser_profile import LaserProfile
from onestroke.errors import InputError
from onestroke.paths import check_input_file

GCODE_SUFFIXES = (".gcode", ".nc", ".gc", ".ngc")
DRAWING_SUFFIXES = (".svg", ".svgz", ".json")
RASTER_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tif", ".tiff", ".webp")


def playable_suffixes() -> tuple[str, ...]:
    """Every extension `player_data_for_file` accepts (with the dot, lower case)."""
    from fabrication.embroidery.read import readable_extensions

    return readable_extensions() + GCODE_SUFFIXES + DRAWING_SUFFIXES + RASTER_SUFFIXES


def player_data_for_file(path: str | os.PathLike, *, stitches_per_minute: float = 600.0,
                         trim_seconds: float = 10.0,
                         hoop: tuple[float, float, float, float] | None = None,
                         laser_profile: LaserProfile | None = None) -> PlayerData:
    """`PlayerData` of an embroidery file, a G-code file or a drawing (.svg, .json, raster).

    Raster images are vectorized with the default options; the vectorizer's warnings are
    in the result's `warnings`. stitches_per_minute, trim_seconds, hoop: embroidery only;
    laser_profile: G-code only (None: the default profile).
    """
    path = str(path)
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in playable_suffixes():
        raise InputError(f"cannot play {path!r}; use an embroidery file (.pes, .dst, .jef, .exp, "
                         f".vp3, ...), G-code ({', '.join(GCODE_SUFFIXES)}) or a drawing "
                         f"(.svg, .json, .png, .jpg)")
    check_input_file(path)
    title = os.path.basename(path)
    if suffix in GCODE_SUFFIXES:
        from fabrication.player.from_gcode import gcode_file_player_data

        return gcode_file_player_data(path, profile=laser_profile)
    if suffix in DRAWING_SUFFIXES + RASTER_SUFFIXES:
        from dataclasses import replace

        from fabrication.player.from_drawing import drawing_player_data

        warnings: tuple[str, ...] = ()
        if suffix == ".json":
            from vectorize.svg_write import read_drawing_json

            drawing = read_drawing_json(path)
        else:
            from vectorize import VectorizeOptions, vectorize_file

            result = vectorize_file(path, VectorizeOptions())
            drawing, warnings = result.drawing, tuple(result.report.warnings)
        return replace(drawing_player_data(drawing, title=title), warnings=warnings)
    from fabrication.player.from_embroidery import embroidery_file_player_data

    return embroidery_file_player_data(path, stitches_per_minute=stitches_per_minute,
                                       trim_seconds=trim_seconds, hoop=hoop)
