"""`onestroke embroider`: a drawing (PNG/JPG/SVG/JSON) to an embroidery file sewn along the curve."""

from __future__ import annotations

import os
import time

import click

from fabrication.cli.common import console, done, edits_option, step, warn
from fabrication.cli.options import (Integer, Length, Number, Percent, drawing_input_options, input_argument,
                                     output_option, placement_options)
from fabrication.embroidery.arrows import ARROW_SIZE
from fabrication.embroidery.columns import CORNER_ANGLE, MITRE_LIMIT, OVERLAP
from fabrication.embroidery.plan import MAX_STITCH, MIN_STITCH, MIN_STROKE, TRIM_DISTANCE
from fabrication.embroidery.preview import PREVIEW_WIDTH
from fabrication.embroidery.running import STITCH_LENGTH, TOLERANCE
from fabrication.embroidery.satin import (MAX_WIDTH, MIN_WIDTH, PULL_PERCENT, RANDOM_WIDTH, SEED, SHORT_DISTANCE,
                                          SHORT_INSET, SPLIT_LENGTH, UNDERLAY_INSET, UNDERLAY_SPACING, WIDTH_SCALE)
from fabrication.embroidery.triple import REPEATS
from fabrication.embroidery.zigzag import PULL_COMPENSATION, SPACING, STITCH_WIDTH
from machines.hoops import SPM
from onestroke.atomic import all_or_nothing
from onestroke.errors import InputError
from onestroke.paths import check_distinct


def source_date() -> str:
    """JEF's date: SOURCE_DATE_EPOCH (reproducible builds) when set, else a fixed value."""
    import datetime

    from fabrication.embroidery.plan import FIXED_DATE

    value = os.environ.get("SOURCE_DATE_EPOCH")
    if value is None or not value.strip():
        return FIXED_DATE
    try:
        moment = datetime.datetime.fromtimestamp(int(value), tz=datetime.timezone.utc)
    except (ValueError, OverflowError, OSError):
        raise InputError(f"SOURCE_DATE_EPOCH {value!r} is not a number of seconds since 1970") from None
    return moment.strftime("%Y%m%d%H%M%S")


@click.command()
@input_argument()
@output_option(help="Embroidery file to write: .pes, .dst, .jef, .exp or .vp3.")
@click.option("--style", type=click.Choice(["running", "triple", "zigzag", "satin", "arrows"]), default="running",
              show_default=True, help="Stitch style (satin: a column as wide as the drawn line).")
@placement_options(default_size="90mm")
@click.option("--hoop", default="100x100", show_default=True,
              help="Hoop: 100x100 (4x4), 130x180 (5x7), 150x250, 160x260 (6x10), 200x200, or WxH in mm.")
@click.option("--fit", is_flag=True, help="Scale the design down to fit the hoop instead of refusing it.")
@click.option("--stitch-length", type=Length(STITCH_LENGTH), default=None,
              help=f"Running/triple stitch and the arrows' centre walk, {STITCH_LENGTH.span()} and at least "
                   "--min-stitch "
                   "[default: 2.5mm].")
@click.option("--tolerance", type=Length(TOLERANCE), default=None,
              help=f"Largest chord-to-curve distance, {TOLERANCE.span()} [default: 0.2mm].")
@click.option("--stitch-width", "--zigzag-width", "stitch_width", type=Length(STITCH_WIDTH), default=None,
              help=f"Zigzag width rail to rail [2mm], a constant satin width [the drawn width] or arrow spread "
                   f"[2.5mm]; {STITCH_WIDTH.span()}.")
@click.option("--spacing", type=Length(SPACING), default=None,
              help=f"Zigzag and satin peak-to-peak spacing [0.4mm] or arrow spacing [5mm]; {SPACING.span()}.")
@click.option("--pull-comp", type=Length(PULL_COMPENSATION), default=None,
              help=f"Pull compensation added to the width (both sides), {PULL_COMPENSATION.span()} "
                   "[zigzag 0.2mm, satin 0mm].")
@click.option("--pull-comp-percent", type=Percent(PULL_PERCENT), default=None,
              help=f"Satin: pull compensation as a share of the width, {PULL_PERCENT.span()} [0%].")
@click.option("--width-scale", type=Number(WIDTH_SCALE), default=None,
              help=f"Satin: the drawn width times this, {WIDTH_SCALE.span()} [1].")
@click.option("--min-width", type=Length(MIN_WIDTH), default=None,
              help=f"Satin: narrowest column, {MIN_WIDTH.span()} [0.5mm].")
@click.option("--max-width", type=Length(MAX_WIDTH), default=None,
              help=f"Satin: widest column, {MAX_WIDTH.span()} [8mm].")
@click.option("--repeats", type=Integer(REPEATS), default=None,
              help=f"Triple stitch: back-and-forth passes, {REPEATS.span()} [default: 1].")
@click.option("--arrow-size", type=Length(ARROW_SIZE), default=None,
              help=f"Arrows: arm length along the curve, {ARROW_SIZE.span()} [default: 2mm].")
@click.option("--underlay", default=None,
              help="Underlay: center, edge, zigzag or none [zigzag: center when wider than 1.5mm]; satin also "
                   "kinds joined by + (edge+zigzag) and auto [auto: center to 2mm, edge to 4mm, edge+zigzag "
                   "wider].")
@click.option("--underlay-inset", type=Length(UNDERLAY_INSET), default=None,
              help=f"Satin: edge walk inside the rails, {UNDERLAY_INSET.span()} [0.4mm; the zigzag underlay half].")
@click.option("--underlay-spacing", type=Length(UNDERLAY_SPACING), default=None,
              help=f"Zigzag and satin: zigzag underlay peak to peak, {UNDERLAY_SPACING.span()} [3mm].")
@click.option("--short-stitch-distance", type=Length(SHORT_DISTANCE), default=None,
              help=f"Satin: short stitches where points on a rail come closer, {SHORT_DISTANCE.span()} [0.25mm].")
@click.option("--short-stitch-inset", type=Percent(SHORT_INSET), default=None,
              help=f"Satin: how far short stitches end inside the rail, {SHORT_INSET.span()} of the width [15%].")
@click.option("--split-length", type=Length(SPLIT_LENGTH), default=None,
              help=f"Satin: wider rows are split into stitches this long at most, {SPLIT_LENGTH.span()} [7mm].")
@click.option("--random-width", type=Percent(RANDOM_WIDTH), default=None,
              help=f"Satin: each row's reach varies by up to this, each side, {RANDOM_WIDTH.span()} [0%].")
@click.option("--random-phase", is_flag=True, help="Satin: split stitches at a random phase (seeded).")
@click.option("--seed", type=Integer(SEED), default=None, help=f"Satin: seed of the random options, {SEED.span()} [0].")
@click.option("--corner-angle", type=Number(CORNER_ANGLE), default=None,
              help=f"Zigzag and satin: corners sharper than this are mitred or split, {CORNER_ANGLE.span()} [45].")
@click.option("--mitre-limit", type=Number(MITRE_LIMIT), default=None,
              help=f"Zigzag and satin: a mitre reaching further (half widths) is split instead, "
                   f"{MITRE_LIMIT.span()} [2].")
@click.option("--corner-overlap", type=Length(OVERLAP), default=None,
              help=f"Zigzag and satin: split and mitred columns overlap by this, {OVERLAP.span()} [0.3mm].")
@click.option("--min-stroke", type=Length(MIN_STROKE), default="1mm", show_default=True,
              help="Shorter strokes join a neighbour within --trim-distance by travel stitches, or are "
                   f"left out with a warning; {MIN_STROKE.span()}.")
@click.option("--min-stitch", type=Length(MIN_STITCH), default="0.3mm", show_default=True,
              help=f"Shorter stitches are merged away (locks excepted); {MIN_STITCH.span()}.")
@click.option("--max-stitch", type=Length(MAX_STITCH), default="12.1mm", show_default=True,
              help=f"Longest needle-down stitch per axis, {MAX_STITCH.span()} (never above the format's limit).")
@click.option("--trim-distance", type=Length(TRIM_DISTANCE), default="3mm", show_default=True,
              help=f"Strokes further apart are joined by lock, trim and jump; {TRIM_DISTANCE.span()}.")
@click.option("--lock", "lock_form", type=click.Choice(["half", "back_forth"]), default="half",
              show_default=True, help="Lock/tack form.")
@click.option("--color", "--colour", "color", default=None,
              help="Thread colour (#rrggbb or a name), or a comma-separated list, one per stroke in "
                   "drawing order [default: the SVG's stroke colours, else black].")
@click.option("--thread-chart", type=click.Choice(["brother", "janome", "husqvarna", "viking", "janome-sew"]),
              default=None, help="Pick the nearest thread of one of pyembroidery's catalogues and print its number.")
@click.option("--name", "design_name", default=None,
              help="Design name stored in .pes/.dst [default: the input file's stem].")
@click.option("--start", default=None,
              help="Where sewing starts: X,Y in mm from the design centre (y down), or 'reverse'.")
@click.option("--pes-version", type=Integer(), default=None,
              help="PES version: 6 (default; keeps RGB colours) or 1 (Brother's 64-colour palette).")
@click.option("--spm", type=Number(SPM), default=None,
              help=f"Machine speed in stitches per minute, {SPM.span()} [default: 600].")
@output_option(".png", ".svg", flags=("--preview",), dest="preview_path", required=False,
               help="Also write a preview image (.png or .svg).")
@click.option("--preview-width", type=Integer(PREVIEW_WIDTH), default=1000, show_default=True,
              help=f"Preview width, {PREVIEW_WIDTH.span()}.")
@click.option("--preview-style", type=click.Choice(["realistic", "diagnostic"]), default="realistic",
              show_default=True,
              help="realistic: thread on fabric; diagnostic: needle points, jumps, trims, order, hoop.")
@click.option("--preview-hoop", is_flag=True, help="Draw the hoop in the realistic preview too.")
@drawing_input_options(prefix="Raster input: ")
@edits_option
def embroider(source: str, output: str, style: str, size: float | None, width: float | None,
              height: float | None, rotate: float, hoop: str, fit: bool, stitch_length: float | None,
              tolerance: float | None, stitch_width: float | None, spacing: float | None,
              pull_comp: float | None, repeats: int | None, arrow_size: float | None, underlay: str | None,
              min_stroke: float, min_stitch: float, max_stitch: float, trim_distance: float, lock_form: str,
              color: str | None, thread_chart: str | None, design_name: str | None, start: str | None,
              pes_version: int | None, spm: float | None, preview_path: str | None, preview_width: int,
              preview_style: str, preview_hoop: bool, multi: bool, threshold: float | None, blur: float,
              classifier: str, edits: str | None, **column) -> None:
    """Sew SOURCE (PNG/JPG/SVG/JSON drawing) along its curve into an embroidery file."""
    from fabrication.job_options import embroidery_settings
    from fabrication.embroidery.canvas import check_preview_path
    from fabrication.embroidery.export import write_embroidery
    from fabrication.embroidery.pipeline import embroider as embroider_drawing
    from fabrication.embroidery.preview import PreviewOptions, render_stitch_preview

    started = time.perf_counter()
    # Every option is checked before anything is read or written.
    check_distinct(inputs=[("input", source), ("--edits file", edits)],
                   outputs=[("output", output), ("--preview", preview_path)])
    settings = embroidery_settings(
        output=output, style=style, size=size, width=width, height=height, rotate=rotate, hoop=hoop, fit=fit,
        stitch_length=stitch_length, tolerance=tolerance, stitch_width=stitch_width, spacing=spacing,
        pull_comp=pull_comp, repeats=repeats, arrow_size=arrow_size, underlay=underlay,
        min_stroke=min_stroke, min_stitch=min_stitch, max_stitch=max_stitch, trim_distance=trim_distance,
        lock_form=lock_form, color=color, thread_chart=thread_chart, start=start, name=design_name,
        source=source, date=source_date(), pes_version=pes_version, spm=spm, **column)
    if preview_path is not None:
        check_preview_path(preview_path)
        preview_options = PreviewOptions(width=preview_width, style=preview_style,
                                         hoop=preview_hoop or preview_style == "diagnostic")
    job = settings.job
    the_hoop = job.hoop
    for message in settings.warnings:
        warn(message)

    if source.lower().endswith(".json"):
        from vectorize.svg_write import read_drawing_json

        drawing = read_drawing_json(source)
    else:
        from fabrication.cli.common import read_drawing

        with step(f"reading {os.path.basename(source)}") as progress:
            drawing = read_drawing(source, multi=multi, threshold=threshold, blur=blur,
                                   classifier=classifier, edits=edits, progress=progress)
    with step("planning the stitches") as progress:
        result = embroider_drawing(drawing, job, progress=progress)
    with all_or_nothing():  # the file and its preview appear together, or neither does
        with step(f"writing {os.path.basename(output)}"):
            write_embroidery(result.plan, output, pes_version=pes_version)
        if preview_path is not None:
            with step("drawing the preview"):
                render_stitch_preview(result.plan, preview_path, hoop=the_hoop, stats=result.stats,
                                      options=preview_options)

    for message in result.warnings:
        warn(message)
    stats = result.stats
    for line in stats.lines():
        console.print(line, soft_wrap=True)
    extra = f" and {preview_path}" if preview_path else ""
    done(f"wrote {output}{extra}: {stats.stitches} stitches, {stats.trims} trims, "
         f"{stats.thread_length / 1000:.2f} m thread (+ {stats.bobbin_length / 1000:.2f} m bobbin), "
         f"{stats.width:.1f} x {stats.height:.1f} mm "
         f"in hoop {the_hoop.name}, sewing about {stats.seconds / 60:.1f} min "
         f"(made in {time.perf_counter() - started:.1f} s)")
