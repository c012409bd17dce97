"""Reading a user's text file (G-code, profiles) with one-line errors for every way it fails."""

from __future__ import annotations

import os

from onestroke.errors import InputError


def read_text(path: str | os.PathLike, *, what: str = "file", expect: str = "a text file") -> str:
    """The UTF-8 text of `path`; InputError naming `what` when missing, a folder, not text."""
    name = str(path)
    try:
        with open(path, encoding="utf-8", errors="strict") as handle:
            return handle.read()
    except FileNotFoundError:
        raise InputError(f"{what} {name!r} does not exist") from None
    except IsADirectoryError:
        raise InputError(f"{what} {name!r} is a directory; give {expect}") from None
    except UnicodeDecodeError:
        raise InputError(f"{what} {name!r} is not text; give {expect}") from None
    except OSError as error:
        raise InputError(f"cannot read {what} {name!r}: {error.strerror}") from None
