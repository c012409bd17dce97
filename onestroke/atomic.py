"""Atomic file writes: a failed run leaves no half-written file and never clobbers a good one.

Every file is written to a temporary file beside its target, synced, and renamed over it.
Inside `all_or_nothing()` the renames wait for the end of the block: the outputs of one
command (an embroidery file and its preview, G-code and its frame file, an SVG and its
stage images) appear together, or, if anything fails first, none of them does and every
temporary file (and folder made for them) is removed.

Errors follow the exit-code rule (onestroke.errors): a folder that cannot take files,
found by `check_writable` / `check_folder` before any work, is an `InputError`; anything
that fails while writing (disk full, I/O error, a folder gone meanwhile) is an `OutputError`.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from onestroke.errors import InputError, OutputError

# errno values that mean "no room" rather than "not allowed": a work failure (exit 1) even
# when found before any work
_NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def os_reason(error: OSError) -> str:
    """An OSError's cause in words ("the disk is full", "the file system is read-only")."""
    reasons = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
               errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
               errno.EPERM: "operation not permitted",
               errno.EFBIG: "the file is too large for this system",
               errno.ENOENT: "the folder cannot hold files", errno.EIO: "input/output error",
               errno.ENOTDIR: "a part of the path is a file, not a folder"}
    return reasons.get(error.errno) or error.strerror or type(error).__name__


def _probe(folder: Path, what: str) -> None:
    """Create and remove an empty file in `folder`: the one test that tells a folder that takes
    files from a read-only, immutable, special (/proc) or forbidden one, for root too."""
    try:
        fd, name = tempfile.mkstemp(prefix=".onestroke-probe-", dir=folder)
    except OSError as error:
        why = {errno.EROFS: "is on a read-only file system", errno.EACCES: "is not writable (permission denied)",
               errno.EPERM: "takes no new files (operation not permitted: an immutable folder?)",
               errno.ENOENT: "cannot hold files (a special folder, such as /proc)"}
        message = f"{what}: folder {str(folder)!r} {why.get(error.errno) or 'cannot take files: ' + os_reason(error)}"
        if error.errno in _NO_ROOM:
            raise OutputError(message, errno=error.errno) from None
        raise InputError(message) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(name)


def check_writable(path: str | os.PathLike) -> Path:
    """Raise `InputError` unless `path` can be created (its folder exists and takes files)."""
    path = _check_path(path)
    _probe(path.parent if str(path.parent) else Path("."), f"cannot write {str(path)!r}")
    return path


def _check_path(path: str | os.PathLike) -> Path:
    """`check_writable` short of trying the folder: names a missing folder or a file in the way."""
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
    return path


def check_folder(folder: str | os.PathLike, *, what: str, parents: bool = False) -> Path:
    """Raise `InputError` unless `folder` is, or can be made as, a folder that takes files.

    For an output folder that is made if missing (batch -o, --debug): then its parent must
    be a folder that takes files (as `mkdir` without -p: a mistyped path is not made), or
    with `parents` its nearest existing ancestor. what: the option, for messages.
    """
    folder = Path(folder)
    there = folder if folder.exists() else (folder.parent if str(folder.parent) else Path("."))
    while parents and not there.exists() and there != there.parent:
        there = there.parent
    if there.exists() and not there.is_dir():
        raise InputError(f"{what} {str(folder)!r}: {str(there)!r} is a file, not a folder")
    if not there.exists():
        raise InputError(f"{what} {str(folder)!r}: folder {str(there)!r} does not exist")
    _probe(there, f"{what} {str(folder)!r}")
    return folder


class OutputSet:
    """The files of one `all_or_nothing()` block: written aside, renamed together at the end."""

    def __init__(self) -> None:
        self._staged: dict[Path, str] = {}  # target -> its synced temporary file
        self._folders: list[Path] = []      # folders made for the outputs, outermost first

    def stage(self, temporary: str, target: Path) -> None:
        earlier = self._staged.pop(target, None)
        if earlier is not None:  # written twice in one block: the last content wins
            with contextlib.suppress(OSError):
                os.unlink(earlier)
        self._staged[target] = temporary

    def staged(self) -> tuple[Path, ...]:
        """The targets waiting for `commit`, in the order they were written."""
        return tuple(self._staged)

    def made_folder(self, folder: Path) -> None:
        self._folders.append(folder)

    def commit(self) -> None:
        """Rename every temporary file over its target. A rename needs no room on the disk,
        so past the last write only an I/O error can stop this half way."""
        while self._staged:
            target, temporary = next(iter(self._staged.items()))
            try:
                os.replace(temporary, target)
            except OSError as error:
                self.discard()
                raise OutputError(f"cannot write {str(target)!r}: {os_reason(error)}", errno=error.errno) from None
            del self._staged[target]
        self._folders.clear()

    def discard(self) -> None:
        """Remove every temporary file, and the folders made for them if left empty."""
        for temporary in self._staged.values():
            with contextlib.suppress(OSError):
                os.unlink(temporary)
        self._staged.clear()
        for folder in reversed(self._folders):
            with contextlib.suppress(OSError):
                folder.rmdir()
        self._folders.clear()


_current: contextvars.ContextVar[OutputSet | None] = contextvars.ContextVar("onestroke_outputs", default=None)


@contextlib.contextmanager
def all_or_nothing() -> Iterator[OutputSet]:
    """Every file written by `atomic_open` (and the folders made by `make_folder`) in this
    block appears when the block ends, or none does if it raises (Ctrl-C included).

    A block inside another one joins it. The set is per thread/context: a studio's server
    thread writing meanwhile is not part of it.
    """
    outer = _current.get()
    if outer is not None:
        yield outer
        return
    outputs = OutputSet()
    token = _current.set(outputs)
    try:
        yield outputs
    except BaseException:
        outputs.discard()
        raise
    else:
        outputs.commit()
    finally:
        _current.reset(token)


def make_folder(folder: str | os.PathLike) -> Path:
    """`folder` and its missing parents, made; inside `all_or_nothing()` they are removed
    again if the block fails. OSError becomes `OutputError`."""
    folder = Path(folder)
    missing = []
    ancestor = folder
    while not ancestor.exists() and ancestor != ancestor.parent:
        missing.append(ancestor)
        ancestor = ancestor.parent
    outputs = _current.get()
    for part in reversed(missing):
        try:
            part.mkdir()
        except FileExistsError:
            continue
        except OSError as error:
            raise OutputError(f"cannot make folder {str(part)!r}: {os_reason(error)}", errno=error.errno) from None
        if outputs is not None:
            outputs.made_folder(part)
    return folder


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "wb") -> Iterator[IO]:
    """Open a temporary file beside `path`; rename it over `path` only if the block succeeds
    (inside `all_or_nothing()`: when that block ends).

    Any OSError of the file system (disk full, read-only, permission, /proc) becomes an
    `OutputError` naming `path`; the temporary file is removed either way.
    """
    try:
        path = _check_path(path)
    except InputError as error:  # checked before the work, so something changed since
        raise OutputError(str(error)) from None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent or ".")
    except OSError as error:
        raise OutputError(f"cannot write {str(path)!r}: {os_reason(error)}", errno=error.errno) from None
    outputs = _current.get()
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": "\n"})) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
        if outputs is None:
            os.replace(tmp, path)
        else:
            outputs.stage(tmp, path)
    except BaseException as error:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(error, OSError):
            raise OutputError(f"cannot write {str(path)!r}: {os_reason(error)}", errno=error.errno) from None
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write `data` to `path` atomically."""
    with atomic_open(path, "wb") as handle:
        handle.write(data)


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write `text` (UTF-8, `\\n` line endings) to `path` atomically."""
    with atomic_open(path, "w") as handle:
        handle.write(text)
