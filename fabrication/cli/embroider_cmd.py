"""`onestroke embroider`: a drawing (PNG/JPG/SVG/JSON) to an embroidery file sewn along the curve."""

from __future__ import annotations

import os
import time

import click

from fabrication.cli.common import console, done, edits_option
from onestroke.atomic import check_writable
from onestroke.errors import InputError


def warn(message: str) -> None:
    """A one-line warning (soft wrap: long messages stay on one line in logs)."""
    console.print(f"[yellow]warning:[/yellow] {message}", soft_wrap=True)

@click.command()
@click.argument("source", type=click.Path(path_type=str))
@click.option("-o", "--output", required=True, type=click.Path(path_type=str),
              help="Embroidery file to write: .pes, .dst, .jef, .exp or .vp3.")
@click.option("--style", default="running", show_default=True,
              help="Stitch style: running, triple, zigzag or arrows.")
@click.option("--size", default=None, help="Longest side of the design, e.g. 90mm, 3.5in [default: 90mm].")
@click.option("--width", default=None, help="Width of the design instead of --size.")
@click.option("--height", default=None, help="Height of the design instead of --size.")
@click.option("--rotate", type=float, default=0.0, show_default=True, help="Degrees, counter-clockwise.")
@click.option("--hoop", default="100x100", show_default=True,
              help="Hoop: 100x100 (4x4), 130x180 (5x7), 150x250, 160x260 (6x10), 200x200, or WxH in mm.")
@click.option("--fit", is_flag=True, help="Scale the design down to fit the hoop instead of refusing it.")
@click.option("--stitch-length", default=None,
              help="Running/triple stitch and the arrows' centre walk [default: 2.5mm].")
@click.option("--tolerance", default=None, help="Largest chord-to-curve distance [default: 0.2mm].")
@click.option("--stitch-width", "--zigzag-width", "stitch_width", default=None,
              help="Zigzag width rail to rail [2mm] or arrow spread [2.5mm].")
@click.option("--spacing", default=None, help="Zigzag peak-to-peak spacing [0.4mm] or arrow spacing [5mm].")
@click.option("--pull-comp", default=None, help="Zigzag pull compensation added to the width [default: 0.2mm].")
@click.option("--repeats", type=int, default=None, help="Triple stitch: back-and-forth passes [default: 1].")
@click.option("--arrow-size", default=None, help="Arrows: arm length along the curve [default: 2mm].")
@click.option("--min-stitch", default="0.3mm", show_default=True,
              help="Shorter stitches are merged away (locks excepted).")
@click.option("--max-stitch", default="12.1mm", show_default=True,
              help="Longest needle-down stitch per axis (never above the format's limit).")
@click.option("--trim-distance", default="3mm", show_default=True,
              help="Strokes further apart are joined by lock, trim and jump.")
@click.option("--lock", "lock_form", default="half", show_default=True, help="Lock/tack form: half or back_forth.")
@click.option("--color", "--colour", "color", default="#000000", show_default=True,
              help="Thread colour: #rrggbb or a name.")
@click.option("--pes-version", type=int, default=None,
              help="PES version: 6 (default; keeps RGB colours) or 1 (Brother's 64-colour palette).")
@click.option("--spm", type=float, default=None, help="Machine speed in stitches per minute [default: 600].")
@click.option("--preview", "preview_path", default=None, type=click.Path(path_type=str),
              help="Also write a preview image (.png or .svg).")
@click.option("--preview-width", type=int, default=1000, show_default=True, help="Preview width in px.")
@click.option("--multi", is_flag=True, help="Raster input: multi-stroke vectorization.")
@click.option("--threshold", type=float, default=None, help="Raster input: ink threshold in (0, 1).")
@click.option("--blur", type=float, default=0.0, show_default=True, help="Raster input: Gaussian blur sigma in px.")
@click.option("--classifier", default="cnn", show_default=True,
              help="Raster input: crossing classifier, cnn or geometric.")
@edits_option
def embroider(source: str, output: str, style: str, size: str | None, width: str | None, height: str | None,
              rotate: float, hoop: str, fit: bool, stitch_length: str | None, tolerance: str | None,
              stitch_width: str | None, spacing: str | None, pull_comp: str | None, repeats: int | None,
              arrow_size: str | None, min_stitch: str, max_stitch: str, trim_distance: str, lock_form: str,
              color: str, pes_version: int | None, spm: float | None, preview_path: str | None,
              preview_width: int, multi: bool, threshold: float | None, blur: float,
              classifier: str, edits: str | None) -> None:
    """Sew SOURCE (PNG/JPG/SVG/JSON drawing) along its curve into an embroidery file."""
    from fabrication.cli.job_options import embroidery_settings
    from fabrication.embroidery.canvas import check_preview_path
    from fabrication.embroidery.export import write_embroidery
    from fabrication.embroidery.pipeline import embroider as embroider_drawing
    from fabrication.embroidery.preview import PreviewOptions, render_stitch_preview

    started = time.perf_counter()
    # Every option is checked before anything is read or written.
    settings = embroidery_settings(
        output=output, style=style, size=size, width=width, height=height, rotate=rotate, hoop=hoop, fit=fit,
        stitch_length=stitch_length, tolerance=tolerance, stitch_width=stitch_width, spacing=spacing,
        pull_comp=pull_comp, repeats=repeats, arrow_size=arrow_size, min_stitch=min_stitch,
        max_stitch=max_stitch, trim_distance=trim_distance, lock_form=lock_form, color=color,
        pes_version=pes_version, spm=spm)
    check_writable(output)
    if preview_path is not None:
        check_preview_path(preview_path)
        check_writable(preview_path)
        preview_options = PreviewOptions(width=preview_width)
    if not os.path.isfile(source):
        raise InputError(f"input file {source!r} does not exist")
    job = settings.job
    the_hoop = job.hoop
    for message in settings.warnings:
        warn(message)

    if source.lower().endswith(".json"):
        from vectorize.svg_write import drawing_from_json

        with open(source, encoding="utf-8") as handle:
            drawing = drawing_from_json(handle.read())
    else:
        from fabrication.cli.common import read_drawing

        drawing = read_drawing(source, multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                               edits=edits)
    result = embroider_drawing(drawing, job)
    write_embroidery(result.plan, output, pes_version=pes_version)
    if preview_path is not None:
        render_stitch_preview(result.plan, preview_path, hoop=the_hoop, stats=result.stats,
                              options=preview_options)

    for message in result.warnings:
        warn(message)
    stats = result.stats
    for line in stats.lines():
        console.print(line, soft_wrap=True)
    extra = f" and {preview_path}" if preview_path else ""
    done(f"wrote {output}{extra}: {stats.stitches} stitches, {stats.trims} trims, "
         f"{stats.thread_length / 1000:.2f} m thread, {stats.width:.1f} x {stats.height:.1f} mm "
         f"in hoop {the_hoop.name}, about {stats.seconds / 60:.1f} min "
         f"({time.perf_counter() - started:.1f} s)")
