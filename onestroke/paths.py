"""Input and output paths of one command: outputs never overwrite an input or each other.

Two names are the same file when they resolve to the same path (symlinks, `..`, case on
case-insensitive systems) or, for files that exist, share a device and inode (hard links).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from onestroke.errors import InputError


def _identity(path: str | os.PathLike) -> tuple:
    """What makes two names the same file: (device, inode) if it exists, else the resolved path."""
    try:
        info = os.stat(path)
        return ("inode", info.st_dev, info.st_ino)
    except OSError:
        return ("path", os.path.normcase(str(Path(path).resolve())))


def check_distinct(*, inputs: Iterable[tuple[str, str | os.PathLike | None]],
                   outputs: Iterable[tuple[str, str | os.PathLike | None]]) -> None:
    """Refuse any output that is one of the inputs or another output.

    `inputs` and `outputs` are (what, path) pairs, e.g. ("input", "a.png"), ("--preview", p);
    None paths are skipped. Raises `InputError` naming both roles and the file.
    """
    seen: dict[tuple, str] = {}
    for role, path in inputs:
        if path is not None:
            seen.setdefault(_identity(path), role)
    for role, path in outputs:
        if path is None:
            continue
        key = _identity(path)
        if key in seen:
            raise InputError(f"{role} {str(path)!r} is the same file as the {seen[key]}; writing it would "
                             "destroy that, give another file name")
        seen[key] = role
