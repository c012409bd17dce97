"""Helpers shared by the CLI commands: reading a drawing from any input, console output."""

from __future__ import annotations

import click
from rich.console import Console

# Status goes to stderr so that stdout stays clean for piping.
console = Console(stderr=True, highlight=False)


def warn(message: str) -> None:
    """Print a one-line warning (soft wrap: long messages stay on one line in logs)."""
    console.print(f"[yellow]warning:[/yellow] {message}", soft_wrap=True)


def done(message: str) -> None:
    """Print a one-line summary of what a command made."""
    click.echo(message)


def read_drawing(path: str, options=None):
    """Read a drawing from a raster image or SVG (`options`: a `VectorizeOptions`, default
    ones if None), printing the vectorizer's warnings."""
    from vectorize import VectorizeOptions, vectorize_file

    result = vectorize_file(path, options or VectorizeOptions())
    for message in result.report.warnings:
        warn(message)
    return result.drawing
