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


def _kind(mode: int) -> str | None:
    """What a file that is not a regular file is, in a user's words; None for a regular file."""
    import stat

    kinds = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
    return next((name for test, name in kinds if test(mode)), None)


def check_input_file(path: str | os.PathLike, *, what: str = "input file", expect: str = "a file") -> str:
    """`path` as a string if it names a readable regular file, else `InputError` saying which
    way it is not: missing, a broken symbolic link, a directory, a FIFO or device (reading
    one would block or never end: /dev/zero), or unreadable."""
    name = os.fspath(path)
    try:
        info = os.stat(name)
    except FileNotFoundError:
        if os.path.islink(name):
            raise InputError(f"{what} {name!r} is a symbolic link to {os.readlink(name)!r}, which does not "
                             "exist") from None
        raise InputError(f"{what} {name!r} does not exist") from None
    except OSError as error:
        raise InputError(f"cannot read {what} {name!r}: {error.strerror}") from None
    kind = _kind(info.st_mode)
    if kind is not None:
        target = f" (a link to {os.path.realpath(name)!r})" if os.path.islink(name) else ""
        raise InputError(f"{what} {name!r}{target} is {kind}, not a regular file; give {expect}")
    if not os.access(name, os.R_OK):
        raise InputError(f"{what} {name!r} is not readable (permission denied)")
    return name
