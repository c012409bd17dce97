"""`onestroke inkscape install`: the Inkscape extension, put where Inkscape finds it."""

from __future__ import annotations

import sys

import click

from fabrication.cli.common import done
from onestroke.atomic import all_or_nothing, check_folder
from onestroke.errors import InputError


@click.group()
def inkscape() -> None:
    """The Inkscape extension (Extensions > onestroke > Single-line vectorize)."""


@inkscape.command()
@click.option("--user", is_flag=True, help="Into Inkscape's user extensions folder (the default).")
@click.option("--dir", "folder", type=click.Path(file_okay=False), default=None,
              help="Into this folder instead (e.g. a system-wide extensions folder).")
def install(user: bool, folder: str | None) -> None:
    """Install the extension; it runs onestroke with this Python."""
    from fabrication.bridges.inkscape_install import install_extension, user_extensions_folder

    if user and folder is not None:
        raise InputError("give --user or --dir, not both")
    target = folder if folder is not None else user_extensions_folder()
    # tried before any work; Inkscape's own folder may not exist yet on a fresh install
    check_folder(target, what="--dir" if folder is not None else "Inkscape's extensions folder",
                 parents=folder is None)
    with all_or_nothing():  # the extension's files appear together, or none does
        installed = install_extension(target, python=sys.executable)
    for path in installed.files:
        click.echo(str(path))
    done(f"Inkscape extension installed in {installed.folder} (runs onestroke with {installed.python}); "
         "restart Inkscape, then Extensions > onestroke > Single-line vectorize")
