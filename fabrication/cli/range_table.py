"""The table of every numeric option's range, read from the declarations the commands use.

docs/cli.md carries this table between its `ranges` markers (tests/onestroke/test_option_ranges.py
checks that it is the same); after changing a declaration, regenerate it with
`python -m fabrication.cli.range_table`.
"""

from __future__ import annotations

import click

from fabrication.cli import COMMANDS, main
from fabrication.cli.options import _Ranged

BEGIN, END = "<!-- ranges: begin (python -m fabrication.cli.range_table) -->", "<!-- ranges: end -->"


def ranged_options() -> list[tuple[str, str, str]]:
    """(command, flag, range) of every numeric option with a declared range, in --help order."""
    rows = []
    with click.Context(main) as context:
        for name in COMMANDS:
            command = main.get_command(context, name)
            for param in command.params:
                if isinstance(param, click.Option) and isinstance(param.type, _Ranged):
                    limits = param.type.limits
                    if limits.low is not None or limits.high is not None:
                        rows.append((name, max(param.opts, key=len), limits.span()))
    return rows


def markdown() -> str:
    """The table as docs/cli.md holds it, markers included: one row per option and range,
    naming the commands that take it."""
    commands: dict[tuple[str, str], list[str]] = {}
    for command, flag, span in ranged_options():
        commands.setdefault((flag, span), []).append(command)
    lines = [BEGIN, "| option | range | commands |", "|---|---|---|"]
    lines += [f"| `{flag}` | {span} | {', '.join(names)} |" for (flag, span), names in commands.items()]
    return "\n".join(lines + [END])


if __name__ == "__main__":
    print(markdown())
