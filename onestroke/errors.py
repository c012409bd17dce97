"""The one exception hierarchy of onestroke, and the exit-code rule it carries.

Every error class holds the exit code the command line gives for it:

- 2: the request was wrong, found before any work: a bad input file or option, an output
  folder that does not exist, is read-only or cannot take files (`InputError`);
- 1: the work failed: the disk filled up, a device or a scheduler was lost, the vectorizer
  or a machine refused (`OnestrokeError` and its other subclasses);
- 130: interrupted by Ctrl-C, SIGTERM or SIGHUP (`Interrupted`, and Python's own
  `KeyboardInterrupt`).

Messages are one line, name the offending value and say what would be accepted.
"""

EXIT_FAILED = 1
EXIT_BAD_REQUEST = 2
EXIT_INTERRUPTED = 130


class OnestrokeError(Exception):
    """Root of every error onestroke raises on purpose."""

    exit_code = EXIT_FAILED


class InputError(OnestrokeError, ValueError):
    """The user gave something we cannot use: a bad file, option, size or path."""

    exit_code = EXIT_BAD_REQUEST


class VectorizeError(OnestrokeError):
    """The vectorizer could not produce a drawing from otherwise valid input."""


class FabricationError(OnestrokeError):
    """Stitches, toolpaths or previews could not be made."""


class MachineError(OnestrokeError):
    """Talking to a machine failed: port, protocol, alarm or error reply."""


class OutputError(OnestrokeError):
    """A file could not be written while the work ran: disk full, I/O error, a folder gone.
    errno: the OSError's number when one was the cause (ENOSPC...), else None."""

    def __init__(self, message: str, *, errno: int | None = None) -> None:
        super().__init__(message)
        self.errno = errno


class Cancelled(OnestrokeError):
    """The caller stopped a computation it no longer wanted (the studio: a newer edit)."""


class Interrupted(KeyboardInterrupt):
    """Stopped on purpose by a signal (SIGTERM, SIGHUP): handled everywhere Ctrl-C is (a
    `KeyboardInterrupt`, so no `except Exception` swallows it); the argument names the signal."""

    exit_code = EXIT_INTERRUPTED
