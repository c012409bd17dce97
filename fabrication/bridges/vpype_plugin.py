"""`vpype onestroke DRAWING`: onestroke's ordered curve as a vpype layer (the `vpype` extra).

Registered through the `vpype.plugins` entry point. The drawing is vectorized by the library,
placed like `onestroke vectorize --size` (`placement.place_on_page`: the design's box on a page
of its physical size, or the input's own page at 96 dpi) and handed to vpype in its unit, CSS
px (1/96 in): each stroke one line, flattened within --tolerance, in drawing order and
direction. The layer's pen width is the measured ink width; the page size is set when the
document has none yet. vpype's `linesort`, `linemerge`, `reloop` and `splitall` change the
order, the direction or the start of lines: docs/integrations.md lists pipelines that keep it.
"""

from __future__ import annotations

import click
import vpype as vp
import vpype_cli

from onestroke.errors import OnestrokeError

PX_PER_MM = 96 / 25.4


@click.command()
@click.argument("drawing", type=vpype_cli.PathType(exists=True, dir_okay=False))
@click.option("--multi", is_flag=True, help="Multi-stroke drawing: keep every ink piece, several lines.")
@click.option("--threshold", type=vpype_cli.FloatType(), default=None,
              help="Ink threshold, a gray level in (0, 1) (default: Li's method).")
@click.option("--blur", type=vpype_cli.FloatType(), default=0.0, help="Gaussian blur sigma in px (0-25).")
@click.option("--classifier", type=vpype_cli.ChoiceType(["cnn", "geometric"]), default="cnn",
              help="How crossings are told from touchings.")
@click.option("--size", type=vpype_cli.LengthType(), default=None,
              help="Longest side of the design (e.g. 90mm; default: the drawing's pixels at 96 dpi).")
@click.option("--width", type=vpype_cli.LengthType(), default=None, help="Width of the design instead.")
@click.option("--height", type=vpype_cli.LengthType(), default=None, help="Height of the design instead.")
@click.option("--tolerance", type=vpype_cli.LengthType(), default="0.05mm",
              help="Largest distance of the lines from the curve (default: 0.05mm).")
@click.option("-l", "--layer", type=vpype_cli.LayerType(accept_new=True), default=None,
              help="Target layer or 'new' (default: a new layer).")
@vpype_cli.global_processor
def onestroke(document: vp.Document, drawing: str, multi: bool, threshold: float | None, blur: float,
              classifier: str, size: float | None, width: float | None, height: float | None,
              tolerance: float, layer: int | None) -> vp.Document:
    """Vectorize DRAWING (PNG/JPG/SVG) into its ordered curve(s), added as a layer."""
    from fabrication.placement import PlacementOptions, place_on_page
    from vectorize import VectorizeOptions, vectorize_file

    if not tolerance > 0:
        raise click.BadParameter(f"--tolerance {tolerance:g} px must be greater than zero")
    try:  # every option is checked (by the option types) before any work
        options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier)
        sides = {"size": size, "width": width, "height": height}
        placement = None
        if any(v is not None for v in sides.values()):
            placement = PlacementOptions(**{k: None if v is None else v / PX_PER_MM for k, v in sides.items()})
        placed = place_on_page(vectorize_file(drawing, options).drawing, placement)
    except OnestrokeError as error:
        raise click.ClickException(str(error)) from None
    lines = vp.LineCollection()
    for stroke in placed.strokes:
        points = stroke.flatten(tolerance / PX_PER_MM) * PX_PER_MM
        lines.append(points[:, 0] + 1j * points[:, 1])
    target = vpype_cli.single_to_layer_id(layer, document)
    document.add(lines, target)
    document.layers[target].set_property(vp.METADATA_FIELD_PEN_WIDTH, placed.stroke_width * PX_PER_MM)
    if document.page_size is None:
        document.page_size = (placed.width * PX_PER_MM, placed.height * PX_PER_MM)
    return document


onestroke.help_group = "Plugins"
