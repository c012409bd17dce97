"""`onestroke laser`: a drawing (PNG/JPG/SVG) to GRBL 1.1 laser G-code, with time and preview."""

from __future__ import annotations

import os
import time
from pathlib import Path

import click

from fabrication.cli.common import console, done, edits_option, warn
from onestroke.atomic import check_writable
from onestroke.errors import InputError


def frame_path_for(output: str) -> str:
    """OUT.gcode -> OUT.frame.gcode (the framing program written beside the job)."""
    root, ext = os.path.splitext(output)
    return f"{root}.frame{ext or '.gcode'}"


@click.command()
@click.argument("source", type=click.Path(path_type=str))
@click.option("-o", "--output", required=True, type=click.Path(path_type=str),
              help="G-code file to write (.gcode, .nc or .gc).")
@click.option("--size", default=None, help="Longest side of the design, e.g. 80mm, 3in.")
@click.option("--width", default=None, help="Width of the design instead of --size.")
@click.option("--height", default=None, help="Height of the design instead of --size.")
@click.option("--rotate", type=float, default=0.0, show_default=True, help="Degrees, counter-clockwise.")
@click.option("--origin", type=click.Choice(["lower-left", "center"]), default="lower-left", show_default=True,
              help="lower-left: design's lower-left corner at machine (0,0); center: design centred on the bed.")
@click.option("--feed", default="1500mm/min", show_default=True, help="Burn speed, e.g. 1500mm/min, 25mm/s.")
@click.option("--power", default="60%", show_default=True, help="Laser power, percent of the profile's max S ($30).")
@click.option("--passes", type=int, default=1, show_default=True, help="Times the job is burned.")
@click.option("--tolerance", default="0.02mm", show_default=True,
              help="Largest distance of the burned path from the drawing.")
@click.option("--arcs", is_flag=True, help="Emit G2/G3 arcs fitted within the tolerance (fewer lines).")
@click.option("--keep-order", is_flag=True, help="Burn strokes in drawing order and direction (no travel optimisation).")
@click.option("--profile", "profile_path", default=None, type=click.Path(path_type=str),
              help="Laser profile TOML (bed, $30, rates, accelerations...); default: built-in 400x400 mm.")
@click.option("--air-assist/--no-air-assist", default=None, help="Switch air assist (M8) on; default: the profile's.")
@click.option("--return-home", is_flag=True, help="End the job with G0 X0 Y0.")
@click.option("--frame", is_flag=True, help="Also write OUT.frame.gcode tracing the bounding box.")
@click.option("--frame-power", default="0%", show_default=True,
              help="Power of the framing trace; 0% keeps the laser off.")
@click.option("--preview", "preview_path", default=None, type=click.Path(path_type=str),
              help="Write a preview image of the job (.png or .svg).")
@click.option("--raster-interval", default="0.1mm", show_default=True,
              help="Line interval of the raster engraving the time is compared with.")
@click.option("--raster-feed", default=None,
              help="Scan speed of that raster engraving; default: --feed (the same burn per mm).")
@click.option("--multi", is_flag=True, help="Raster input: multi-stroke vectorization.")
@click.option("--threshold", type=float, default=None, help="Raster input: ink threshold in (0, 1).")
@click.option("--classifier", type=click.Choice(["cnn", "geometric"]), default="cnn", show_default=True,
              help="Raster input: how the vectorizer tells crossings from touchings.")
@click.option("--port", default=None, help="After writing, stream the job to this serial port (sim:// for a dry run).")
@click.option("--baud", type=int, default=115200, show_default=True, help="Baud rate for --port.")
@edits_option
def laser(source: str, output: str, size: str | None, width: str | None, height: str | None, rotate: float,
          origin: str, feed: str, power: str, passes: int, tolerance: str, arcs: bool, keep_order: bool,
          profile_path: str | None, air_assist: bool | None, return_home: bool, frame: bool, frame_power: str,
          preview_path: str | None, raster_interval: str, raster_feed: str | None, multi: bool, threshold: float | None,
          classifier: str, port: str | None, baud: int, edits: str | None) -> None:
    """Turn SOURCE (PNG/JPG/SVG) into G-code for a GRBL 1.1 laser in one continuous pass per stroke."""
    from fabrication.cli.common import read_drawing
    from fabrication.cli.job_options import laser_settings
    from fabrication.laser.framing import framing_lines
    from fabrication.laser.gcode_write import write_gcode
    from fabrication.laser.job_time import format_duration
    from fabrication.laser.program import laser_program
    from fabrication.laser.raster_time import raster_time
    from onestroke.units import parse_fraction, parse_positive_length, parse_speed

    started = time.perf_counter()
    # every option is checked before anything is read or written
    if os.path.splitext(output)[1].lower() not in (".gcode", ".nc", ".gc", ".ngc", ".txt"):
        raise InputError(f"cannot write {output!r}: use a .gcode, .nc or .gc output file")
    check_writable(output)
    if preview_path is not None:
        if os.path.splitext(preview_path)[1].lower() not in (".png", ".svg"):
            raise InputError(f"preview {preview_path!r} must end in .png or .svg")
        check_writable(preview_path)
    frame_file = frame_path_for(output) if frame else None
    if frame_file:
        check_writable(frame_file)
    outputs = [Path(p).resolve() for p in (output, preview_path, frame_file, source) if p is not None]
    if len(set(outputs)) < len(outputs):
        twice = next(str(p) for p in outputs if outputs.count(p) > 1)
        raise InputError(f"input, output, preview and frame files must all differ ({twice!r} is given twice)")
    settings = laser_settings(size=size, width=width, height=height, rotate=rotate, origin=origin, feed=feed,
                              power=power, passes=passes, tolerance=tolerance, arcs=arcs, keep_order=keep_order,
                              profile_path=profile_path, air_assist=air_assist, return_home=return_home)
    profile = settings.profile
    frame_fraction = parse_fraction(frame_power, what="--frame-power")
    interval = parse_positive_length(raster_interval, what="--raster-interval")
    feed_mm = settings.gcode.feed
    raster_feed_mm = feed_mm if raster_feed is None else parse_speed(raster_feed, what="--raster-feed")
    if not raster_feed_mm > 0:
        raise InputError(f"--raster-feed {raster_feed!r} must be greater than 0 mm/min")
    for message in settings.warnings:
        warn(message)
    if not os.path.exists(source):
        raise InputError(f"input file {source!r} does not exist")

    with console.status(f"reading {os.path.basename(source)}"):
        drawing = read_drawing(source, multi=multi, threshold=threshold, classifier=classifier, edits=edits)
    with console.status("planning the toolpath"):
        program = laser_program(drawing, profile, settings.toolpath, settings.gcode, name=Path(source).name)
    toolpath, job, lines = program.toolpath, program.time, list(program.lines)
    w, h = toolpath.size
    frame_lines = framing_lines(toolpath.bounds, profile, power=frame_fraction) if frame_file else None
    # everything that can refuse the input runs before the first file is written
    raster = raster_time(toolpath, profile, interval=interval, feed=raster_feed_mm)
    write_gcode(output, lines)
    if frame_file:
        write_gcode(frame_file, frame_lines)
    if preview_path is not None:
        from fabrication.laser.preview import render_gcode_preview

        render_gcode_preview(output, preview_path, profile=profile)

    if toolpath.dropped:
        warn(f"{toolpath.dropped} stroke(s) of zero length left out")
    console.print(f"travel: {toolpath.travel_before:.1f} mm in drawing order -> {toolpath.travel_greedy:.1f} mm "
                  f"greedy -> {toolpath.travel_after:.1f} mm after 2-opt")
    console.print(f"time: {format_duration(job.total_seconds)} by GRBL's planner model "
                  f"(length/feed says {format_duration(job.naive_seconds)}); as a raster at "
                  f"{interval:g} mm and {raster_feed_mm:g} mm/min: {format_duration(raster.seconds)}")
    made = [output] + ([frame_file] if frame_file else []) + ([preview_path] if preview_path else [])
    done(f"{', '.join(made)}: {len(lines)} lines, {toolpath.segment_count} moves, burn "
         f"{toolpath.burn_length:.0f} mm, {w:.1f} x {h:.1f} mm, estimated {format_duration(job.total_seconds)}, "
         f"{time.perf_counter() - started:.2f} s")
    if port is not None:
        from fabrication.cli.stream_cmd import run_stream

        # the estimate above was printed first: the user sees the job time before it runs
        run_stream(output, port=port, baud=baud, check=False, frame=False, profile=profile_path)
