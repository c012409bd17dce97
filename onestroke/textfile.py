"""Reading a user's text file (G-code, profiles) with one-line errors for every way it fails."""

from __future__ import annotations

import os

from onestroke.errors import InputError
from onestroke.paths import check_input_file


def read_text(path: str | os.PathLike, *, what: str = "file", expect: str = "a text file") -> str:
    """The text of `path` (UTF-8, else Latin-1 when it is plainly text); InputError naming
    `what` when missing, a folder, or not text (NUL or control bytes)."""
    name = check_input_file(path, what=what, expect=expect)
    try:
        with open(path, "rb") as handle:
            data = handle.read()
    except FileNotFoundError:
        raise InputError(f"{what} {name!r} does not exist") from None
    except IsADirectoryError:
        raise InputError(f"{what} {name!r} is a directory; give {expect}") from None
    except OSError as error:
        raise InputError(f"cannot read {what} {name!r}: {error.strerror}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        pass
    # Not UTF-8: a comment typed in an old editor (Latin-1 "°", "µ") is still text; a file
    # with NUL bytes or mostly control bytes is not.
    controls = sum(1 for b in data[:65536] if b < 32 and b not in (9, 10, 12, 13))
    if b"\0" in data or controls > len(data[:65536]) // 100:
        raise InputError(f"{what} {name!r} is not text; give {expect}")
    return data.decode("latin-1")
