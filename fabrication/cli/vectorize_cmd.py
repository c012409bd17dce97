"""`onestroke vectorize`: a drawing (PNG/JPG/SVG) to an ordered SVG or JSON curve."""

from __future__ import annotations

import os
import time

import click

from fabrication.cli.common import console, done, edits_option, step, warn
from fabrication.cli.options import drawing_input_options, input_argument, output_option, placement_options
from onestroke.atomic import all_or_nothing, check_folder
from onestroke.errors import InputError
from onestroke.paths import check_distinct

# Set before numpy's first import (the options' decorators below bring it): OpenBLAS's
# thread pool, a thread per core, spins waiting for work after numpy's import, ~0.23 s of CPU
# per process on a second core (a process importing the command's libraries: 0.93 -> 0.70 s
# CPU on this 2-core machine), while the command's linear algebra is on vectors and 2-3
# column matrices, far below the sizes OpenBLAS splits between threads (the same SVG bytes
# either way: benchmarks/same_svg.py). A value the user set is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


@click.command()
@input_argument()
@output_option(".svg", ".json", help="Output file: .svg (one path per stroke) or .json (control points).")
@drawing_input_options
@click.option("--debug", "debug_dir", type=click.Path(file_okay=False, path_type=str), default=None,
              help="Write a PNG overlay of every stage into this folder.")
@edits_option
@placement_options()
@click.option("--inkstitch", type=click.Choice(["running", "triple", "zigzag", "satin"]), default=None,
              help="Write an SVG in mm that Ink/Stitch sews: this stitch's parameters on every path.")
def vectorize(source: str, output: str, multi: bool, threshold: float | None, blur: float,
              classifier: str, debug_dir: str | None, edits: str | None, size: float | None,
              width: float | None, height: float | None, rotate: float, inkstitch: str | None) -> None:
    """Vectorize SOURCE into one ordered cubic Bézier curve (or several with --multi).

    With --size (or --width, --height, --rotate) or --inkstitch the output is in mm at the
    design's physical size (without a size: the input's pixels read at 96 dpi)."""
    if inkstitch is not None and not output.lower().endswith(".svg"):
        raise InputError(f"--inkstitch writes an SVG; {output!r} is not a .svg file")
    if debug_dir is not None and os.path.exists(debug_dir) and not os.path.isdir(debug_dir):
        raise InputError(f"--debug {debug_dir!r} is a file; give a folder for the stage images")
    if debug_dir is not None:
        check_folder(debug_dir, what="--debug")
    stage_images = []
    if debug_dir:  # the overlay module is imported only when --debug asks for it
        from vectorize.debug_overlay import STAGE_IMAGES

        stage_images = [("--debug image", os.path.join(debug_dir, name)) for name in STAGE_IMAGES]
    check_distinct(inputs=[("input", source), ("--edits file", edits)], outputs=[("output", output), *stage_images])
    placement = None  # the page at the design's size; None: the input's own page (in mm with --inkstitch)
    if any(v is not None for v in (size, width, height)) or rotate:
        from fabrication.placement import PlacementOptions

        placement = PlacementOptions(size=size, width=width, height=height, rotate=rotate)
    from fabrication.cli.heap import keep_freed_memory, loading_for_good, touch_heap_beside
    from onestroke.cores import idle_cores
    from onestroke.lasting import load_later_imports_for_good

    # Before the binarize thread starts: its freed arrays serve the later stages. With a core
    # to spare, the heap's first pages are touched there while this thread imports.
    if keep_freed_memory() and idle_cores() > 1:
        touch_heap_beside()
    # The libraries load with the garbage collector paused and then stay out of its passes
    # (fabrication/cli/heap.py); a raster drawing's stages load now for that.
    with loading_for_good():
        from vectorize import VectorizeOptions, vectorize_file
        from vectorize.pipeline import start_vectorizing

        options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                                   keep_stages=debug_dir is not None, whole_image_confidence=debug_dir is not None)
        # Without edits (which may change the threshold and blur), the drawing is read now and
        # binarized on a spare core while the later stages' libraries load (the binarizing
        # mostly runs outside the GIL, the imports hold it): the same ink, sooner.
        binarizing = start_vectorizing(source, options, edits=edits is not None)
        from vectorize.svg_write import write_drawing
    load_later_imports_for_good()  # onnxruntime and networkx where the drawing needs them

    replay = None
    if edits is not None:  # the edits module only when there are edits to replay
        from vectorize.refine.edits import read_edits

        replay = read_edits(edits)
    started = time.perf_counter()
    with step(f"vectorizing {os.path.basename(source)}") as progress:
        result = vectorize_file(source, options, edits=replay, progress=progress, binarizing=binarizing)
    for message in result.report.warnings:
        warn(message)
    drawing = result.drawing
    if inkstitch is not None or placement is not None:
        from fabrication.placement import place_on_page

        drawing = place_on_page(drawing, placement)
    written = []
    with all_or_nothing():  # the drawing and its stage images appear together, or none does
        if inkstitch is not None:
            from fabrication.bridges.inkstitch import inkstitch_svg
            from onestroke.atomic import atomic_write_text

            atomic_write_text(output, inkstitch_svg(drawing, inkstitch))
        else:
            write_drawing(drawing, output)
        if debug_dir is not None:
            from vectorize.debug_overlay import write_debug_images

            written = write_debug_images(result, debug_dir)
    if written:
        console.print(f"debug: {len(written)} stage images in {debug_dir}")
    report = result.report
    done(f"{output}: {report.strokes} stroke{'s' * (report.strokes != 1)}, "
         f"{report.intersections} intersection{'s' * (report.intersections != 1)}, "
         f"{time.perf_counter() - started:.2f} s")
