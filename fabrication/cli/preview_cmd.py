"""`onestroke preview`: a picture of an embroidery file, a G-code file or a drawing.

Dispatch by the input's extension: G-code goes to the laser preview, .svg/.json drawings
to the drawing preview, and anything pyembroidery reads to the stitch preview.
"""

from __future__ import annotations

import os

import click

from fabrication.cli.common import console, done, step, warn
from fabrication.cli.options import Integer, Number, input_argument, output_option
from fabrication.embroidery.preview import PREVIEW_WIDTH
from machines.hoops import SPM
from onestroke.errors import InputError
from onestroke.paths import check_distinct




GCODE_SUFFIXES = (".gcode", ".nc", ".gc", ".ngc")
DRAWING_SUFFIXES = (".svg", ".svgz", ".json")


@click.command()
@input_argument()
@output_option(".png", ".svg", ".html", ".htm", help="Preview to write: an image (.png, .svg) or a player page (.html).")
@click.option("--width", "width_px", type=Integer(PREVIEW_WIDTH), default=1000, show_default=True,
              help=f"Image width, {PREVIEW_WIDTH.span()} (embroidery and drawings).")
@click.option("--hoop", default=None, help="Embroidery: draw this hoop, e.g. 100x100 or 5x7.")
@click.option("--spm", type=Number(SPM), default=None,
              help=f"Embroidery: stitches per minute for the time, {SPM.span()} [600].")
def preview(source: str, output: str, width_px: int, hoop: str | None, spm: float | None) -> None:
    """Draw SOURCE (.pes/.dst/.jef/.exp/.vp3/... , .gcode/.nc, or an .svg/.json drawing) as OUTPUT.

    An .html OUTPUT is a self-contained player (no server, no network) that plays the
    stitches, laser moves or pen in order, with time, scrubber, speed and zoom."""
    from fabrication.embroidery.canvas import check_preview_path
    from fabrication.embroidery.read import readable_extensions

    suffix = os.path.splitext(source)[1].lower()
    accepted = readable_extensions() + GCODE_SUFFIXES + DRAWING_SUFFIXES
    if suffix in accepted:  # an unknown kind is refused for that first, below or by the player
        check_distinct(inputs=[("input", source)], outputs=[("output", output)])
    if output.lower().endswith((".html", ".htm")):
        return _player_page(source, output, hoop, spm)
    if suffix not in accepted:
        raise InputError(f"cannot preview {source!r}; use an embroidery file "
                         f"({', '.join(readable_extensions()[:8])}, ...), G-code "
                         f"({', '.join(GCODE_SUFFIXES)}) or a drawing (.svg, .json)")

    if suffix in GCODE_SUFFIXES:
        from fabrication.laser.preview import render_gcode_preview

        with step(f"drawing {os.path.basename(source)}") as progress:
            job = render_gcode_preview(source, output, progress=progress)
        minutes, seconds = divmod(int(round(job.total_seconds)), 60)
        done(f"wrote {output}: laser job about {minutes} min {seconds:02d} s")
        return

    check_preview_path(output)
    from fabrication.embroidery.preview import PreviewOptions

    # A file's preview tells the truth (needle points, jumps, trims, order), as before.
    options = PreviewOptions(width=width_px, style="diagnostic")
    if suffix in DRAWING_SUFFIXES:
        from fabrication.embroidery.preview import render_drawing_preview

        if suffix == ".json":
            from vectorize.svg_write import read_drawing_json

            drawing = read_drawing_json(source)
        else:
            from fabrication.cli.common import read_drawing

            with step(f"reading {os.path.basename(source)}") as progress:
                drawing = read_drawing(source, progress=progress)
        with step("drawing the preview"):
            render_drawing_preview(drawing, output, options)
        done(f"wrote {output}: {len(drawing.strokes)} stroke(s), length {drawing.length:.1f} {drawing.unit}")
        return

    from fabrication.embroidery.preview import render_stitch_preview
    from fabrication.embroidery.read import read_embroidery
    from fabrication.embroidery.stats import embroidery_stats
    from machines.hoops import load_embroidery_profile

    profile = load_embroidery_profile()
    the_hoop = profile.hoop(hoop) if hoop is not None else None
    with step(f"reading {os.path.basename(source)}"):
        read = read_embroidery(source)
    stats = embroidery_stats(read.plan, stitches_per_minute=spm or profile.stitches_per_minute,
                             trim_seconds=profile.trim_seconds, color_changes=read.color_changes)
    with step("drawing the preview"):
        render_stitch_preview(read.plan, output, hoop=the_hoop, stats=stats, options=options)
    for message in stats.warnings:
        warn(message)
    for line in stats.lines():
        console.print(line, soft_wrap=True)
    done(f"wrote {output}: {stats.stitches} stitches, {stats.trims} trims, "
         f"{stats.width:.1f} x {stats.height:.1f} mm")


def _player_page(source: str, output: str, hoop: str | None, spm: float | None) -> None:
    """`preview SOURCE -o PAGE.html`: the standalone player page."""
    from fabrication.player import player_data_for_file, write_player_html
    from machines.hoops import load_embroidery_profile

    profile = load_embroidery_profile()  # --spm is range-checked by its option type
    frame = None
    if hoop is not None:
        field = profile.hoop(hoop)
        frame = (-field.width / 2, -field.height / 2, field.width / 2, field.height / 2)
    with step(f"reading {os.path.basename(source)}"):
        data = player_data_for_file(source, stitches_per_minute=spm or profile.stitches_per_minute,
                                    trim_seconds=profile.trim_seconds, hoop=frame)
    for message in data.warnings:
        warn(message)
    write_player_html(data, output, source=source)
    from machines.job_time import format_duration

    span = (format_duration(data.total) if data.time_unit == "s"
            else f"{data.total:.1f} {data.time_unit} drawn")
    plural = "es" if data.number_label.endswith("ch") else "s"
    done(f"wrote {output}: player of {len(data):,} moves, {data.number_total:,} "
         f"{data.number_label}{plural if data.number_total != 1 else ''}, {span}")
