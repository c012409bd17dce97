"""Helpers shared by the CLI commands: reading a drawing from any input, console output."""

from __future__ import annotations

import os
import re
import sys

import click

# rich's console markup tags (rich.markup.RE_TAGS): plain output drops them as rich does
# and keeps a tag escaped with a backslash, without the backslash.
_MARKUP_TAG = re.compile(r"(\\*)\[([a-z#/@][^[]*?)]")


def _plain_text(markup: str) -> str:
    def tag(match: re.Match) -> str:
        slashes, escaped = divmod(len(match.group(1)), 2)
        return "\\" * slashes + (f"[{match.group(2)}]" if escaped else "")

    return _MARKUP_TAG.sub(tag, markup)


def _may_be_terminal() -> bool:
    """False when rich's console could not see a terminal on stderr: stderr is not a tty and
    neither FORCE_COLOR nor TTY_COMPATIBLE asks for one (rich's own rules)."""
    if "FORCE_COLOR" in os.environ or os.environ.get("TTY_COMPATIBLE") == "1":
        return True
    isatty = getattr(sys.stderr, "isatty", None)
    try:
        return bool(isatty and isatty())
    except ValueError:  # a closed stream
        return False


class _StatusConsole:
    """Status output on stderr, so that stdout stays clean for piping. On a terminal it is
    a rich console (colour, spinners, bars); in a log or a pipe plain lines, with the same
    text as rich would write there but unwrapped, and rich is not imported at all: it
    costs ~40 ms of every command's start-up. Anything beyond `print` and `is_terminal`
    goes to the rich console, made on first use."""

    def __init__(self) -> None:
        self._rich = None

    @property
    def rich(self):
        """The rich console (stderr, no highlighting), made on first use."""
        if self._rich is None:
            from rich.console import Console

            self._rich = Console(stderr=True, highlight=False)
        return self._rich

    @property
    def is_terminal(self) -> bool:
        return _may_be_terminal() and self.rich.is_terminal

    def print(self, *objects, soft_wrap: bool = False, highlight: bool | None = None, **options) -> None:
        if self.is_terminal or options or not all(isinstance(o, str) for o in objects):
            self.rich.print(*objects, soft_wrap=soft_wrap, highlight=highlight, **options)
            return
        click.echo(_plain_text(" ".join(objects)), err=True)

    def __getattr__(self, name: str):
        return getattr(self.rich, name)


console = _StatusConsole()


def warn(message: str) -> None:
    """Print a one-line warning (soft wrap: long messages stay on one line in logs)."""
    console.print(f"[yellow]warning:[/yellow] {message}", soft_wrap=True)


# Seconds between plain progress lines when stderr is not a terminal (a log, a pipe):
# the streamer's pace; ONESTROKE_PROGRESS_SECONDS changes it (0: a line at every report).
PROGRESS_EVERY = 5.0


def progress_every(default: float | None = PROGRESS_EVERY) -> float | None:
    """Seconds between plain progress lines: ONESTROKE_PROGRESS_SECONDS, else `default`
    (None: no plain lines)."""
    import math
    import os

    try:
        value = float(os.environ["ONESTROKE_PROGRESS_SECONDS"])
    except (KeyError, ValueError):
        return default
    return value if math.isfinite(value) and value >= 0 else default


class _StepProgress:
    """The display of one step. On a terminal: a spinner and the step's name, then a bar
    with percent and time remaining once the library reports how far it is (transient: it
    goes when the step ends). Elsewhere (a log, a pipe) quiet but for the command's final
    summary, unless ONESTROKE_PROGRESS_SECONDS asks for one plain line every so many
    seconds (then a step shorter than that prints nothing)."""

    def __init__(self, description: str) -> None:
        self.description = description
        self.every = progress_every(default=None)
        self.bar = None
        self.task = None
        self.started = 0.0
        self.next_line = 0.0
        self.stage = None
        self.stage_started = 0.0

    def __enter__(self) -> "_StepProgress":
        import time

        self.started = time.monotonic()
        self.next_line = self.started + (self.every or 0.0)
        if console.is_terminal:
            from rich.progress import (BarColumn, Progress, SpinnerColumn, TaskProgressColumn, TextColumn,
                                       TimeRemainingColumn)

            self.bar = Progress(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(),
                                TaskProgressColumn(), TimeRemainingColumn(), console=console.rich, transient=True)
            self.bar.start()
            self.task = self.bar.add_task(self.description, total=None)
        return self

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.stop()

    def __call__(self, report) -> None:
        """Take one `onestroke.progress.Progress` report."""
        import time

        what = f"{self.description}: {report.stage}" if report.stage else self.description
        if self.bar is not None:
            self.bar.update(self.task, description=what, total=max(report.total, 1),
                            completed=min(report.done, report.total) if report.total else 1)
            return
        now = time.monotonic()
        if report.stage != self.stage:
            self.stage, self.stage_started = report.stage, now
        if self.every is None or now < self.next_line:
            return
        self.next_line = now + self.every
        from machines.job_time import format_duration

        elapsed = now - self.started
        # the rate of this stage so far; its first report has none yet
        spent = now - self.stage_started
        remaining = (f", about {format_duration(spent * (1 - report.fraction) / report.fraction)} left"
                     if 0 < report.fraction < 1 and spent > 0 else "")
        unit = f" {report.unit}" if report.unit else ""
        console.print(f"{what}: {100 * report.fraction:.0f} % ({report.done:,}/{report.total:,}{unit}), "
                      f"elapsed {format_duration(elapsed)}{remaining}", highlight=False, soft_wrap=True)


def step(description: str) -> _StepProgress:
    """`with step("planning the stitches") as progress:` shows the step while it runs; pass
    `progress` to the library call as its progress callback (see `onestroke.progress`).
    On a terminal a transient spinner, then bar; in a log or a pipe nothing but the
    command's final summary (plain lines on request: ONESTROKE_PROGRESS_SECONDS)."""
    return _StepProgress(description)


def done(message: str) -> None:
    """Print a one-line summary of what a command made."""
    click.echo(message)


def read_drawing(path: str, *, multi: bool = False, threshold: float | None = None,
                 blur: float = 0.0, classifier: str = "cnn", edits: str | None = None, progress=None):
    """Read a drawing from a raster image or SVG, printing the vectorizer's warnings.

    edits: path of an edits file (the studio's corrections) to replay; progress: a step's
    progress callback (`step`).
    """
    from fabrication.cli.heap import loading_for_good

    with loading_for_good():  # as `onestroke vectorize` does (fabrication/cli/heap.py)
        from vectorize import VectorizeOptions, vectorize_file
        from vectorize.pipeline import start_vectorizing

        options = VectorizeOptions(multi=multi, threshold=threshold, blur=blur, classifier=classifier)
        # Binarized on a spare core while the later stages load, as `onestroke vectorize` does.
        binarizing = start_vectorizing(path, options, edits=edits is not None)
        from vectorize.refine.edits import read_edits
    from onestroke.lasting import load_later_imports_for_good

    load_later_imports_for_good()  # onnxruntime and networkx where the drawing needs them
    replay = read_edits(edits) if edits is not None else None
    result = vectorize_file(path, options, edits=replay, progress=progress, binarizing=binarizing)
    for message in result.report.warnings:
        warn(message)
    return result.drawing


def edits_option(function):
    """The `--edits FILE` option: replay the studio's corrections of the vectorization."""
    from fabrication.cli.options import InputFile

    return click.option("--edits", "edits", default=None, type=InputFile(),
                        help="Raster input: replay the corrections saved by `onestroke studio` "
                             "(edits JSON; its threshold, blur and mode win over the flags).")(function)
