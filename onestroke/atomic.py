"""Atomic file writes: a failed run leaves no half-written file and never clobbers a good one."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from onestroke.errors import InputError, OutputError


def check_writable(path: str | os.PathLike) -> Path:
    """Raise `InputError` unless `path` can be created (its folder exists and is writable)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise InputError(f"output {str(path)!r} is a directory; give a file name")
    # The nearest existing ancestor tells a missing folder from a file used as a folder.
    ancestor = folder
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise InputError(f"cannot write {str(path)!r}: {str(ancestor)!r} is a file, not a folder")
    if not folder.is_dir():
        raise InputError(f"cannot write {str(path)!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise InputError(f"cannot write {str(path)!r}: folder {str(folder)!r} is not writable")
    return path


def _os_reason(error: OSError) -> str:
    reasons = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
               errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
               errno.EPERM: "operation not permitted", errno.EFBIG: "the file is too large for this system",
               errno.ENOENT: "the folder cannot hold files", errno.EIO: "input/output error"}
    return reasons.get(error.errno) or error.strerror or type(error).__name__


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "wb") -> Iterator[IO]:
    """Open a temporary file beside `path`; rename it over `path` only if the block succeeds.

    Any OSError of the file system (disk full, read-only, permission, /proc) becomes an
    `OutputError` naming `path`; the temporary file is removed either way.
    """
    path = check_writable(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent or ".")
    except OSError as error:
        raise OutputError(f"cannot write {str(path)!r}: {_os_reason(error)}") from None
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": "\n"})) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException as error:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(error, OSError):
            raise OutputError(f"cannot write {str(path)!r}: {_os_reason(error)}") from None
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write `data` to `path` atomically."""
    with atomic_open(path, "wb") as handle:
        handle.write(data)


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write `text` (UTF-8, `\\n` line endings) to `path` atomically."""
    with atomic_open(path, "w") as handle:
        handle.write(text)
