"""`onestroke batch`: files and folders of drawings to SVG, embroidery and G-code files at once."""

from __future__ import annotations

import sys

import click

from fabrication.cli.common import console, done, warn
from onestroke.errors import InputError


def batch_job(to: str, *, multi: bool, threshold: float | None, blur: float, classifier: str,
              embroidery: dict, laser: dict):
    """The `BatchJob` of the option values (`embroidery`/`laser`: keyword arguments of
    `embroidery_settings` / `laser_settings`) and the option warnings, once for the batch."""
    from fabrication.batch.work import DRAWING_EXTENSIONS, LASER_EXTENSIONS, BatchJob, DrawingTarget, \
        EmbroideryTarget, LaserTarget
    from fabrication.cli.job_options import embroidery_settings, laser_settings
    from machines.hoops import load_embroidery_profile
    from vectorize.pipeline import VectorizeOptions

    sewn = tuple(f.extension for f in load_embroidery_profile().formats)
    extensions = list(dict.fromkeys(e.strip().lower().lstrip(".") for e in to.split(",") if e.strip()))
    if not extensions:
        raise InputError("--to names no output; e.g. --to svg,pes,gcode")
    targets, warnings = [], []
    for extension in extensions:
        if extension in DRAWING_EXTENSIONS:
            targets.append(DrawingTarget(extension=extension))
        elif extension in sewn:
            settings = embroidery_settings(output=f"out.{extension}", **embroidery)
            targets.append(EmbroideryTarget(extension=extension, job=settings.job,
                                            pes_version=settings.pes_version))
            warnings += settings.warnings
        elif extension in LASER_EXTENSIONS:
            settings = laser_settings(**laser)
            targets.append(LaserTarget(extension=extension, profile=settings.profile,
                                       toolpath=settings.toolpath, gcode=settings.gcode))
            warnings += settings.warnings
        else:
            known = ", ".join(DRAWING_EXTENSIONS + sewn + LASER_EXTENSIONS)
            raise InputError(f"--to {extension!r} is not an output this batch makes; use some of {known}")
    if embroidery.get("pes_version") is not None and "pes" not in extensions:
        raise InputError("--pes-version applies to --to pes only")
    options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier)
    return BatchJob(vectorize=options, targets=tuple(targets)), tuple(dict.fromkeys(warnings))


def _progress():
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TextColumn,
                               TimeRemainingColumn)
    from rich.text import Text

    class RateColumn(ProgressColumn):
        def render(self, task) -> Text:
            speed = task.finished_speed or task.speed
            return Text(f"{speed:.2f} files/s" if speed else "-- files/s")

    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), RateColumn(),
                    TextColumn("left"), TimeRemainingColumn(), console=console, transient=True)


@click.command()
@click.argument("inputs", nargs=-1, required=True, type=click.Path(path_type=str))
@click.option("-o", "--output-dir", "out_dir", required=True, type=click.Path(file_okay=False, path_type=str),
              help="Folder for the outputs (the input tree is mirrored in it), the report and the manifest.")
@click.option("--to", "to", default="svg", show_default=True,
              help="Outputs per drawing, comma-separated: svg, json, pes, dst, jef, exp, vp3, gcode, nc.")
@click.option("--jobs", "-j", type=int, default=None, help="Worker processes [default: all cores].")
@click.option("--scheduler", default=None,
              help="Run on a Dask distributed cluster at this address (tcp://HOST:PORT); needs onestroke[dask].")
@click.option("--retry-failed", is_flag=True, help="Try again inputs that failed in an earlier run, unchanged.")
@click.option("--multi", is_flag=True, help="Multi-stroke drawings: keep every ink piece.")
@click.option("--threshold", type=float, default=None, help="Ink threshold in (0, 1) [default: Li's method].")
@click.option("--blur", type=float, default=0.0, show_default=True, help="Gaussian blur sigma in px.")
@click.option("--classifier", type=click.Choice(["cnn", "geometric"]), default="cnn", show_default=True,
              help="How crossings are told from touchings.")
@click.option("--size", default=None, help="Longest side of the design [embroidery: 90mm; laser: as drawn].")
@click.option("--width", default=None, help="Width of the design instead of --size.")
@click.option("--height", default=None, help="Height of the design instead of --size.")
@click.option("--rotate", type=float, default=0.0, show_default=True, help="Degrees, counter-clockwise.")
@click.option("--style", default="running", show_default=True, help="Embroidery: running, triple, zigzag or arrows.")
@click.option("--hoop", default="100x100", show_default=True, help="Embroidery: hoop name or WxH in mm.")
@click.option("--fit", is_flag=True, help="Embroidery: scale a design down to fit the hoop.")
@click.option("--stitch-length", default=None, help="Embroidery: running stitch length [2.5mm].")
@click.option("--tolerance", default=None, help="Embroidery: chord-to-curve distance [0.2mm].")
@click.option("--stitch-width", "--zigzag-width", "stitch_width", default=None,
              help="Embroidery: zigzag width [2mm] or arrow spread [2.5mm].")
@click.option("--spacing", default=None, help="Embroidery: zigzag spacing [0.4mm] or arrow spacing [5mm].")
@click.option("--pull-comp", default=None, help="Embroidery: zigzag pull compensation [0.2mm].")
@click.option("--repeats", type=int, default=None, help="Embroidery: triple stitch passes [1].")
@click.option("--arrow-size", default=None, help="Embroidery: arrow arm length [2mm].")
@click.option("--min-stitch", default="0.3mm", show_default=True, help="Embroidery: shortest stitch.")
@click.option("--max-stitch", default="12.1mm", show_default=True, help="Embroidery: longest stitch per axis.")
@click.option("--trim-distance", default="3mm", show_default=True, help="Embroidery: trim between strokes further apart.")
@click.option("--lock", "lock_form", default="half", show_default=True, help="Embroidery: lock form, half or back_forth.")
@click.option("--color", "--colour", "color", default="#000000", show_default=True, help="Embroidery: thread colour.")
@click.option("--pes-version", type=int, default=None, help="Embroidery: PES version 6 (default) or 1.")
@click.option("--spm", type=float, default=None, help="Embroidery: stitches per minute for the time [600].")
@click.option("--origin", type=click.Choice(["lower-left", "center"]), default="lower-left", show_default=True,
              help="Laser: where the design sits on the bed.")
@click.option("--feed", default="1500mm/min", show_default=True, help="Laser: burn speed.")
@click.option("--power", default="60%", show_default=True, help="Laser: power, percent of the profile's max S.")
@click.option("--passes", type=int, default=1, show_default=True, help="Laser: times the job is burned.")
@click.option("--laser-tolerance", default="0.02mm", show_default=True,
              help="Laser: largest distance of the burned path from the drawing (laser's --tolerance).")
@click.option("--arcs", is_flag=True, help="Laser: emit G2/G3 arcs.")
@click.option("--keep-order", is_flag=True, help="Laser: burn strokes in drawing order.")
@click.option("--profile", "profile_path", default=None, type=click.Path(path_type=str),
              help="Laser: profile TOML [built-in 400x400 mm].")
@click.option("--air-assist/--no-air-assist", default=None, help="Laser: air assist (M8) [the profile's].")
@click.option("--return-home", is_flag=True, help="Laser: end with G0 X0 Y0.")
def batch(inputs: tuple[str, ...], out_dir: str, to: str, jobs: int | None, scheduler: str | None,
          retry_failed: bool, multi: bool, threshold: float | None, blur: float, classifier: str,
          size, width, height, rotate, style, hoop, fit, stitch_length, tolerance, stitch_width, spacing,
          pull_comp, repeats, arrow_size, min_stitch, max_stitch, trim_distance, lock_form, color,
          pes_version, spm, origin, feed, power, passes, laser_tolerance, arcs, keep_order, profile_path,
          air_assist, return_home) -> None:
    """Turn every drawing in INPUTS (files, folders searched recursively) into the --to outputs.

    Outputs mirror the input folders under OUT_DIR, with a per-file report
    (onestroke-batch-report.csv/.json). A second run skips outputs that are newer than their
    input and were made with the same options. Exit code 1 if any drawing failed.
    """
    import os

    from fabrication.batch.inputs import find_inputs
    from fabrication.batch.runner import run_batch
    from fabrication.batch.work import INPUT_EXTENSIONS

    placement = dict(size=size, width=width, height=height, rotate=rotate)
    job, warnings = batch_job(
        to, multi=multi, threshold=threshold, blur=blur, classifier=classifier,
        embroidery=dict(placement, style=style, hoop=hoop, fit=fit, stitch_length=stitch_length,
                        tolerance=tolerance, stitch_width=stitch_width, spacing=spacing, pull_comp=pull_comp,
                        repeats=repeats, arrow_size=arrow_size, min_stitch=min_stitch, max_stitch=max_stitch,
                        trim_distance=trim_distance, lock_form=lock_form, color=color,
                        pes_version=pes_version, spm=spm),
        laser=dict(placement, origin=origin, feed=feed, power=power, passes=passes, tolerance=laser_tolerance,
                   arcs=arcs, keep_order=keep_order, profile_path=profile_path, air_assist=air_assist,
                   return_home=return_home))
    if jobs is not None and jobs < 1:
        raise InputError(f"--jobs {jobs} must be at least 1")
    if scheduler is not None and "://" not in scheduler:
        raise InputError(f"--scheduler {scheduler!r} is not an address; e.g. tcp://10.0.0.5:8786")
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError(f"output folder {out_dir!r} is a file")
    items = find_inputs(inputs, out_dir, tuple(t.extension for t in job.targets), INPUT_EXTENSIONS)
    if not items:
        raise InputError(f"no drawings ({', '.join(INPUT_EXTENSIONS)}) found in {', '.join(inputs)}")
    for message in warnings:
        warn(message)

    live = console.is_terminal
    progress = _progress() if live else None
    task = None

    def on_start(to_make: int, skipped: int, failed_before: int) -> None:
        nonlocal task
        if skipped:
            console.print(f"{skipped} of {len(items)} drawings are current: skipped")
        if failed_before:
            console.print(f"{failed_before} drawing{'s' * (failed_before != 1)} failed in an earlier run and "
                          "did not change: not tried again (--retry-failed tries them)")
        if progress is not None and to_make:
            task = progress.add_task("drawings", total=to_make)

    def on_file(record) -> None:
        if record.status == "failed":
            console.print(f"[red]failed:[/red] {record.input}: {record.error}", soft_wrap=True)
        if task is not None:
            progress.advance(task)

    try:
        if progress is not None:
            with progress:
                summary = run_batch(items, job, out_dir, jobs=jobs, scheduler=scheduler,
                                    retry_failed=retry_failed, on_start=on_start, on_file=on_file)
        else:
            summary = run_batch(items, job, out_dir, jobs=jobs, scheduler=scheduler, retry_failed=retry_failed,
                                on_start=on_start, on_file=on_file)
    except KeyboardInterrupt:
        click.echo("interrupted: finished outputs are kept; run the same command again to go on", err=True)
        sys.exit(130)
    where = f"on {scheduler}" if scheduler else f"{summary.workers} worker{'s' * (summary.workers != 1)}"
    done(f"{summary.total} drawings: {summary.ok} made, {summary.skipped} skipped, {summary.failed} failed "
         f"({summary.seconds:.1f} s, {summary.per_second:.2f} drawings/s, {where}); "
         f"report: {summary.report_csv}")
    if summary.failed:
        sys.exit(1)
