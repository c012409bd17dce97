"""`onestroke batch`: files and folders of drawings to SVG, embroidery and G-code files at once."""

from __future__ import annotations

import sys

import click

from fabrication.cli.common import console, done, warn
from fabrication.cli.embroider_cmd import embroider, source_date
from fabrication.job_options import embroidery_settings, laser_settings
from fabrication.cli.laser_cmd import laser
from fabrication.batch.runner import JOBS
from fabrication.cli.options import Integer, drawing_input_options, placement_options
from onestroke.atomic import check_folder
from onestroke.errors import EXIT_INTERRUPTED, InputError, Interrupted


def batch_job(to: str, *, multi: bool, threshold: float | None, blur: float, classifier: str,
              embroidery: dict, laser: dict):
    """The `BatchJob` of the option values (`embroidery`/`laser`: keyword arguments of
    `embroidery_settings` / `laser_settings`) and the option warnings, once for the batch."""
    from fabrication.batch.work import DRAWING_EXTENSIONS, LASER_EXTENSIONS, BatchJob, DrawingTarget, \
        EmbroideryTarget, LaserTarget
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
            return Text(f"{speed:.2f} drawings/s" if speed else "-- drawings/s")

    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), RateColumn(),
                    TextColumn("left"), TimeRemainingColumn(), console=console.rich, transient=True)


def _shared_options(command: click.Command, settings, what: str, renamed: dict | None = None) -> list:
    """Copies of `command`'s options that `settings` (a job_options function) takes, so that
    the batch spells, checks and defaults each option exactly as that command does.
    `renamed`: name -> (flag, new name) for an option that two commands spell the same."""
    import copy
    import inspect

    accepted = set(inspect.signature(settings).parameters) - {"output", *PLACEMENT}
    shared = []
    for param in command.params:
        if isinstance(param, click.Option) and param.name in accepted:
            option = copy.copy(param)
            option.help = f"{what}: {param.help[0].lower()}{param.help[1:]}" if param.help else what
            if param.name in (renamed or {}):
                flag, option.name = renamed[param.name]
                option.opts, option.secondary_opts = [flag], []
            shared.append(option)
    return shared


PLACEMENT = ("size", "width", "height", "rotate")


def _quiet_dask_logs() -> None:
    """Dask logs a lost scheduler as tracebacks on stderr; the batch says it in one line."""
    import logging

    for name in ["distributed", *logging.root.manager.loggerDict]:
        if name.startswith("distributed"):
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)


@click.command()
@click.argument("inputs", nargs=-1, required=True, type=click.Path(path_type=str))
@click.option("-o", "--output-dir", "out_dir", required=True, type=click.Path(file_okay=False, path_type=str),
              help="Folder for the outputs (the input tree is mirrored in it), the report and the manifest.")
@click.option("--to", "to", default="svg", show_default=True,
              help="Outputs per drawing, comma-separated: svg, json, pes, dst, jef, exp, vp3, gcode, nc.")
@click.option("--jobs", "-j", type=Integer(JOBS), default=None, help="Worker processes [default: all cores].")
@click.option("--scheduler", default=None,
              help="Run on a Dask distributed cluster at this address (tcp://HOST:PORT); needs onestroke[dask].")
@click.option("--retry-failed", is_flag=True, help="Try again inputs that failed in an earlier run, unchanged.")
@drawing_input_options
@placement_options(default_size="90mm for embroidery, as drawn for the laser")
def batch(inputs: tuple[str, ...], out_dir: str, to: str, jobs: int | None, scheduler: str | None,
          retry_failed: bool, multi: bool, threshold: float | None, blur: float, classifier: str,
          size: float | None, width: float | None, height: float | None, rotate: float, **options) -> None:
    """Turn every drawing in INPUTS (files, folders searched recursively) into the --to outputs.

    Outputs mirror the input folders under OUT_DIR, with a per-file report
    (onestroke-batch-report.csv/.json). A second run skips outputs that are newer than their
    input and were made with the same options. Exit code 1 if any drawing failed or the
    batch stopped (disk full, scheduler lost; the report says why).
    """
    import os

    from fabrication.batch.inputs import find_inputs
    from fabrication.batch.runner import run_batch
    from fabrication.batch.work import INPUT_EXTENSIONS

    placement = dict(size=size, width=width, height=height, rotate=rotate)
    # the date JEF files store, as `onestroke embroider` sets it; the design name is each input's stem
    embroidery = {**{o.name: options[o.name] for o in EMBROIDERY_OPTIONS}, "date": source_date()}
    laser = {o.name: options[o.name] for o in LASER_OPTIONS}
    laser["tolerance"] = laser.pop("laser_tolerance")
    job, warnings = batch_job(to, multi=multi, threshold=threshold, blur=blur, classifier=classifier,
                              embroidery={**placement, **embroidery}, laser={**placement, **laser})
    if scheduler is not None and "://" not in scheduler:
        raise InputError(f"--scheduler {scheduler!r} is not an address; e.g. tcp://10.0.0.5:8786")
    if scheduler is not None and jobs is not None:
        warnings += (f"--jobs {jobs} has no effect with --scheduler: the cluster's workers run the drawings",)
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError(f"output folder {out_dir!r} is a file")
    check_folder(out_dir, what="output folder")
    items = find_inputs(inputs, out_dir, tuple(t.extension for t in job.targets), INPUT_EXTENSIONS)
    if not items:
        raise InputError(f"no drawings ({', '.join(INPUT_EXTENSIONS)}) found in {', '.join(inputs)}")
    if scheduler is not None:  # the extra and the scheduler, before anything is said or made
        from fabrication.batch.cluster import probe_scheduler, require_dask

        require_dask()
        probe_scheduler(scheduler)
        _quiet_dask_logs()
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
    except KeyboardInterrupt as stop:
        how = f" ({stop})" if isinstance(stop, Interrupted) else ""
        click.echo(f"interrupted{how}: finished outputs are kept; run the same command again to go on", err=True)
        sys.exit(EXIT_INTERRUPTED)
    where = f"on {scheduler}" if scheduler else f"{summary.workers} worker{'s' * (summary.workers != 1)}"
    done(f"{summary.total} drawings: {summary.ok} made, {summary.skipped} skipped, {summary.failed} failed "
         f"({summary.seconds:.1f} s, {summary.per_second:.2f} drawings/s, {where}); "
         f"report: {summary.report_csv}")
    if summary.failed:
        sys.exit(1)


# Embroidery and laser options as `onestroke embroider` and `onestroke laser` declare them;
# the laser's --tolerance is --laser-tolerance here (the embroidery's has the name).
EMBROIDERY_OPTIONS = _shared_options(embroider, embroidery_settings, "Embroidery")
LASER_OPTIONS = _shared_options(laser, laser_settings, "Laser", {"tolerance": ("--laser-tolerance", "laser_tolerance")})
batch.params.extend(EMBROIDERY_OPTIONS + LASER_OPTIONS)
