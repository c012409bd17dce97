"""`onestroke laser`: a drawing (PNG/JPG/SVG) to GRBL 1.1 laser G-code, with time and preview."""

from __future__ import annotations

import os
import time
from pathlib import Path

import click

from fabrication.cli.common import console, done, edits_option, step, warn
from fabrication.cli.options import (Integer, Length, Percent, Speed, drawing_input_options, input_argument,
                                     machine_options, output_option, placement_options)
from fabrication.laser.gcode_write import FEED, PASSES, POWER
from fabrication.laser.raster_time import INTERVAL, RASTER_FEED
from fabrication.laser.toolpath import TOLERANCE
from machines.framing import FRAME_POWER
from onestroke.atomic import all_or_nothing, check_writable
from onestroke.paths import check_distinct


def frame_path_for(output: str) -> str:
    """OUT.gcode -> OUT.frame.gcode (the framing program written beside the job)."""
    root, ext = os.path.splitext(output)
    return f"{root}.frame{ext or '.gcode'}"


@click.command()
@input_argument()
@output_option(".gcode", ".nc", ".gc", ".ngc", ".txt", help="G-code file to write (.gcode, .nc or .gc).")
@placement_options()
@click.option("--origin", type=click.Choice(["lower-left", "center"]), default="lower-left", show_default=True,
              help="lower-left: design's lower-left corner at machine (0,0); center: design centred on the bed.")
@click.option("--feed", type=Speed(FEED), default="1500mm/min", show_default=True,
              help=f"Burn speed, e.g. 1500mm/min, 25mm/s; {FEED.span()}.")
@click.option("--power", type=Percent(POWER), default="60%", show_default=True,
              help=f"Laser power, {POWER.span()} of the profile's max S ($30).")
@click.option("--passes", type=Integer(PASSES), default=1, show_default=True,
              help=f"Times the job is burned, {PASSES.span()}.")
@click.option("--tolerance", type=Length(TOLERANCE), default="0.02mm", show_default=True,
              help=f"Largest distance of the burned path from the drawing, {TOLERANCE.span()}.")
@click.option("--arcs", is_flag=True, help="Emit G2/G3 arcs fitted within the tolerance (fewer lines).")
@click.option("--keep-order", is_flag=True, help="Burn strokes in drawing order and direction (no travel optimisation).")
@click.option("--air-assist/--no-air-assist", default=None, help="Switch air assist (M8) on; default: the profile's.")
@click.option("--return-home", is_flag=True, help="End the job with G0 X0 Y0.")
@click.option("--frame", is_flag=True, help="Also write OUT.frame.gcode tracing the bounding box.")
@click.option("--frame-power", type=Percent(FRAME_POWER), default="0%", show_default=True,
              help=f"Power of the framing trace, {FRAME_POWER.span()}; 0% keeps the laser off.")
@output_option(".png", ".svg", flags=("--preview",), dest="preview_path", required=False,
               help="Write a preview image of the job (.png or .svg).")
@click.option("--raster-interval", type=Length(INTERVAL), default="0.1mm", show_default=True,
              help=f"Line interval of the raster engraving the time is compared with, {INTERVAL.span()} (and "
                   "at most a few hundred million raster pixels).")
@click.option("--raster-feed", type=Speed(RASTER_FEED), default=None,
              help="Scan speed of that raster engraving; default: --feed (the same burn per mm).")
@drawing_input_options(prefix="Raster input: ")
@machine_options(port_help="After writing, stream the job to this serial port (sim:// for a dry run).")
@edits_option
def laser(source: str, output: str, size: float | None, width: float | None, height: float | None, rotate: float,
          origin: str, feed: float, power: float, passes: int, tolerance: float, arcs: bool, keep_order: bool,
          air_assist: bool | None, return_home: bool, frame: bool, frame_power: float, preview_path: str | None,
          raster_interval: float, raster_feed: float | None, multi: bool, threshold: float | None, blur: float,
          classifier: str, port: str | None, baud: int, profile_path: str | None, edits: str | None) -> None:
    """Turn SOURCE (PNG/JPG/SVG) into G-code for a GRBL 1.1 laser in one continuous pass per stroke."""
    from fabrication.cli.common import read_drawing
    from fabrication.job_options import laser_settings
    from fabrication.laser.gcode_write import write_gcode
    from fabrication.laser.program import laser_program
    from fabrication.laser.raster_time import raster_time
    from machines.framing import framing_lines
    from machines.job_time import format_duration

    started = time.perf_counter()
    # every option is checked before anything is read or written
    frame_file = frame_path_for(output) if frame else None
    if frame_file:
        check_writable(frame_file)
    check_distinct(inputs=[("input", source), ("--profile", profile_path), ("--edits file", edits)],
                   outputs=[("output", output), ("--preview", preview_path), ("frame file", frame_file)])
    settings = laser_settings(size=size, width=width, height=height, rotate=rotate, origin=origin, feed=feed,
                              power=power, passes=passes, tolerance=tolerance, arcs=arcs, keep_order=keep_order,
                              profile_path=profile_path, air_assist=air_assist, return_home=return_home)
    profile = settings.profile
    frame_fraction = frame_power / 100.0
    interval = raster_interval
    feed_mm = settings.gcode.feed
    raster_feed_mm = feed_mm if raster_feed is None else raster_feed
    for message in settings.warnings:
        warn(message)

    with step(f"reading {os.path.basename(source)}") as progress:
        drawing = read_drawing(source, multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                               edits=edits, progress=progress)
    with step("planning the toolpath") as progress:
        program = laser_program(drawing, profile, settings.toolpath, settings.gcode, name=Path(source).name,
                                progress=progress)
    toolpath, job, lines = program.toolpath, program.time, list(program.lines)
    w, h = toolpath.size
    frame_lines = framing_lines(toolpath.bounds, power_s=frame_fraction * profile.max_power,
                                max_s=profile.max_power) if frame_file else None
    # everything that can refuse the input runs before the first file is written
    raster = raster_time(toolpath, profile, interval=interval, feed=raster_feed_mm)
    with all_or_nothing():  # the job, its frame file and its preview appear together, or none does
        write_gcode(output, lines)
        if frame_file:
            write_gcode(frame_file, frame_lines)
        if preview_path is not None:
            from fabrication.laser.gcode_write import gcode_text
            from fabrication.laser.preview import render_gcode_preview
            from machines.gcode_program import program_from_text

            with step("drawing the preview") as progress:
                # the preview reads the job as written (the file itself appears only at the end)
                render_gcode_preview(program_from_text(gcode_text(lines), source=output), preview_path,
                                     profile=profile, progress=progress)

    if toolpath.dropped:
        warn(f"{toolpath.dropped} stroke(s) of zero length left out")
    console.print(f"travel: {toolpath.travel_before:.1f} mm in drawing order -> {toolpath.travel_greedy:.1f} mm "
                  f"greedy -> {toolpath.travel_after:.1f} mm after 2-opt")
    console.print(f"time: {format_duration(job.total_seconds)}, {job.bound_text(profile)} "
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
