"""`onestroke vectorize`: a drawing (PNG/JPG/SVG) to an ordered SVG or JSON curve."""

from __future__ import annotations

import os
import time

import click

from fabrication.cli.common import console, done, edits_option, step, warn
from fabrication.cli.options import drawing_input_options, input_argument, output_option
from onestroke.atomic import all_or_nothing, check_folder
from onestroke.errors import InputError
from onestroke.paths import check_distinct


@click.command()
@input_argument()
@output_option(".svg", ".json", help="Output file: .svg (one path per stroke) or .json (control points).")
@drawing_input_options
@click.option("--debug", "debug_dir", type=click.Path(file_okay=False, path_type=str), default=None,
              help="Write a PNG overlay of every stage into this folder.")
@edits_option
def vectorize(source: str, output: str, multi: bool, threshold: float | None, blur: float,
              classifier: str, debug_dir: str | None, edits: str | None) -> None:
    """Vectorize SOURCE into one ordered cubic Bézier curve (or several with --multi)."""
    if debug_dir is not None and os.path.exists(debug_dir) and not os.path.isdir(debug_dir):
        raise InputError(f"--debug {debug_dir!r} is a file; give a folder for the stage images")
    if debug_dir is not None:
        check_folder(debug_dir, what="--debug")
    stage_images = []
    if debug_dir:  # the overlay module is imported only when --debug asks for it
        from vectorize.debug_overlay import STAGE_IMAGES

        stage_images = [("--debug image", os.path.join(debug_dir, name)) for name in STAGE_IMAGES]
    check_distinct(inputs=[("input", source), ("--edits file", edits)], outputs=[("output", output), *stage_images])
    from vectorize import VectorizeOptions, vectorize_file
    from vectorize.edits import read_edits
    from vectorize.svg_write import write_drawing

    replay = read_edits(edits) if edits is not None else None
    started = time.perf_counter()
    options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                               keep_stages=debug_dir is not None)
    with step(f"vectorizing {os.path.basename(source)}") as progress:
        result = vectorize_file(source, options, edits=replay, progress=progress)
    for message in result.report.warnings:
        warn(message)
    written = []
    with all_or_nothing():  # the drawing and its stage images appear together, or none does
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
