"""Helpers shared by the CLI commands: reading a drawing from any input, console output."""

from __future__ import annotations

import click
from rich.console import Console

# Status goes to stderr so that stdout stays clean for piping.
console = Console(stderr=True, highlight=False)


def warn(message: str) -> None:
    """Print a one-line warning."""
    console.print(f"[yellow]warning:[/yellow] {message}")


def done(message: str) -> None:
    """Print a one-line summary of what a command made."""
    click.echo(message)
