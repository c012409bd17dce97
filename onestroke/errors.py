"""The one exception hierarchy of onestroke.

The CLI maps `InputError` (and its subclasses) to exit code 2 and every other
`OnestrokeError` to exit code 1. Messages are one line, name the offending value and say
what would be accepted.
"""


class OnestrokeError(Exception):
    """Root of every error onestroke raises on purpose."""

    exit_code = 1


class InputError(OnestrokeError, ValueError):
    """The user gave something we cannot use: a bad file, option, size or path."""

    exit_code = 2


class VectorizeError(OnestrokeError):
    """The vectorizer could not produce a drawing from otherwise valid input."""


class FabricationError(OnestrokeError):
    """Stitches, toolpaths or previews could not be made."""


class MachineError(OnestrokeError):
    """Talking to a machine failed: port, protocol, alarm or error reply."""


class OutputError(OnestrokeError):
    """A file could not be written: disk full, read-only, permission, a special folder."""


class Cancelled(OnestrokeError):
    """The caller stopped a computation it no longer wanted (the studio: a newer edit)."""
