"""Helpers shared by the CLI commands: reading a drawing from any input, console output."""

from __future__ import annotations

import click
from rich.console import Console

# Status goes to stderr so that stdout stays clean for piping.
console = Console(stderr=True, highlight=False)


def warn(message: str) -> None:
    """Print a one-line warning (soft wrap: long messages stay on one line in logs)."""
    console.print(f"[yellow]warning:[/yellow] {message}", soft_wrap=True)


def step(description: str):
    """A live status line (spinner, stage name) while a step runs, on a terminal only: in a
    log or a pipe nothing but the final summary is printed."""
    return console.status(description)


def done(message: str) -> None:
    """Print a one-line summary of what a command made."""
    click.echo(message)


def read_drawing(path: str, *, multi: bool = False, threshold: float | None = None,
                 blur: float = 0.0, classifier: str = "cnn", edits: str | None = None):
    """Read a drawing from a raster image or SVG, printing the vectorizer's warnings.

    edits: path of an edits file (the studio's corrections) to replay.
    """
    from vectorize import VectorizeOptions, vectorize_file
    from vectorize.edits import read_edits

    replay = read_edits(edits) if edits is not None else None
    result = vectorize_file(path, VectorizeOptions(multi=multi, threshold=threshold, blur=blur,
                                                   classifier=classifier), edits=replay)
    for message in result.report.warnings:
        warn(message)
    return result.drawing


def edits_option(function):
    """The `--edits FILE` option: replay the studio's corrections of the vectorization."""
    from fabrication.cli.options import InputFile

    return click.option("--edits", "edits", default=None, type=InputFile(),
                        help="Raster input: replay the corrections saved by `onestroke studio` "
                             "(edits JSON; its threshold, blur and mode win over the flags).")(function)
