"""`onestroke vectorize`: a drawing (PNG/JPG/SVG) to an ordered SVG or JSON curve."""

from __future__ import annotations

import os
import time

import click

from fabrication.cli.common import console, done, edits_option, warn
from onestroke.atomic import check_writable
from onestroke.errors import InputError


@click.command()
@click.argument("source", type=click.Path(dir_okay=True, path_type=str))
@click.option("-o", "--output", required=True, type=click.Path(path_type=str),
              help="Output file: .svg (one path per stroke) or .json (control points).")
@click.option("--multi", is_flag=True, help="Multi-stroke drawing: keep every ink piece, several strokes.")
@click.option("--threshold", type=float, default=None,
              help="Ink threshold: gray level in (0, 1), paper = 1 after shading correction; "
                   "default: Li's method.")
@click.option("--blur", type=float, default=0.0, show_default=True,
              help="Gaussian blur sigma in px before thresholding (helps pencil scans).")
@click.option("--classifier", type=click.Choice(["cnn", "geometric"]), default="cnn", show_default=True,
              help="How crossings are told from touchings.")
@click.option("--debug", "debug_dir", type=click.Path(file_okay=False, path_type=str), default=None,
              help="Write a PNG overlay of every stage into this folder.")
@edits_option
def vectorize(source: str, output: str, multi: bool, threshold: float | None, blur: float,
              classifier: str, debug_dir: str | None, edits: str | None) -> None:
    """Vectorize SOURCE into one ordered cubic Bézier curve (or several with --multi)."""
    from vectorize import VectorizeOptions, vectorize_file
    from vectorize.edits import read_edits
    from vectorize.svg_write import write_drawing

    suffix = os.path.splitext(output)[1].lower()
    if suffix not in (".svg", ".json"):
        raise InputError(f"cannot write {output!r}: use an .svg or .json output file")
    check_writable(output)
    replay = read_edits(edits) if edits is not None else None
    started = time.perf_counter()
    options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                               keep_stages=debug_dir is not None)
    with console.status(f"vectorizing {os.path.basename(source)}"):
        result = vectorize_file(source, options, edits=replay)
    for message in result.report.warnings:
        warn(message)
    write_drawing(result.drawing, output)
    if debug_dir is not None:
        from vectorize.debug_overlay import write_debug_images

        written = write_debug_images(result, debug_dir)
        if written:
            console.print(f"debug: {len(written)} stage images in {debug_dir}")
    report = result.report
    done(f"{output}: {report.strokes} stroke{'s' * (report.strokes != 1)}, "
         f"{report.intersections} intersection{'s' * (report.intersections != 1)}, "
         f"{time.perf_counter() - started:.2f} s")
