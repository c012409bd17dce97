"""The `onestroke` command line: a thin click layer over the library.

Each command lives in its own module (`vectorize_cmd.py`, `embroider_cmd.py`, ...) and is
registered below. Library errors become a one-line message and an exit code:
2 for bad input (`InputError`), 1 for any other failure; never a traceback.
"""

from __future__ import annotations

import sys

import click

from onestroke.errors import OnestrokeError


class OnestrokeGroup(click.Group):
    """A click group that turns onestroke errors into one-line messages and exit codes."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except OnestrokeError as error:
            click.echo(f"error: {error}", err=True)
            sys.exit(error.exit_code)
        except KeyboardInterrupt:
            click.echo("interrupted", err=True)
            sys.exit(130)
        except MemoryError:
            click.echo("error: out of memory; try a smaller image", err=True)
            sys.exit(1)


@click.group(cls=OnestrokeGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="onestroke")
def main() -> None:
    """Turn line drawings into embroidery files and laser G-code."""


def _register() -> None:
    # Each command lives in its own module; registered here in the order --help lists them.
    from fabrication.cli.embroider_cmd import embroider
    from fabrication.cli.laser_cmd import laser
    from fabrication.cli.ports_cmd import ports
    from fabrication.cli.preview_cmd import preview
    from fabrication.cli.stream_cmd import emulator, stream
    from fabrication.cli.studio_cmd import studio
    from fabrication.cli.train_cmd import train_classifier, validate_classifier
    from fabrication.cli.vectorize_cmd import vectorize

    for command in (vectorize, embroider, laser, stream, preview, studio, ports, emulator, train_classifier,
                    validate_classifier):
        main.add_command(command)


_register()
