"""The batch manifest: which outputs were made from which input with which options.

A small JSON file in the output folder. An output is current when it exists, is not older
than its input and the manifest records it with the same options key; a second run skips
such outputs. An input that failed is remembered with its size and time, so that a rerun
does not try an unchanged bad file again (unless asked to); a failure that was not the
input's (its worker process died) is not remembered. The figures of each input (strokes,
stitches, times) are kept too, for the report rows of a rerun that skips it.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

from fabrication.batch.report import FileStats
from onestroke.atomic import atomic_write_text
from onestroke.errors import InputError
from onestroke.json_check import parse_json

MANIFEST_NAME = "onestroke-batch-manifest.json"
# What `save` writes, as `onestroke.json_check` reads it.
_OUTPUT = {"type": "object", "properties": {"input": {"type": "string"}, "key": {"type": "string"}}}
_FAILED = {"type": "object", "properties": {"key": {"type": "string"}, "error": {"type": "string"},
                                            "stamp": {"type": "array", "minItems": 2, "maxItems": 2,
                                                      "items": {"type": "integer"}}}}
# the figures of `FileStats` (report.py): counts, seconds, warnings
_COUNT, _SECONDS = {"type": "integer", "minimum": 0}, {"type": "number", "minimum": 0}
_STATS = {"type": "object", "properties": {
    "strokes": _COUNT, "intersections": _COUNT, "stitches": _COUNT, "sew_seconds": _SECONDS,
    "laser_seconds": _SECONDS, "seconds": _SECONDS, "warnings": {"type": "array", "items": {"type": "string"}}}}
SCHEMA = {"type": "object", "required": ["format"], "properties": {
    "format": {"const": "onestroke-batch-manifest"},
    "outputs": {"type": "object", "additionalProperties": _OUTPUT},
    "failed": {"type": "object", "additionalProperties": _FAILED},
    "stats": {"type": "object", "additionalProperties": _STATS}}}


def _stamp(path: Path) -> tuple[int, int]:
    stat = path.stat()
    return stat.st_mtime_ns, stat.st_size


class Manifest:
    """Read once at the start, updated per finished file, saved atomically (`save`)."""

    def __init__(self, out_dir: str | os.PathLike) -> None:
        self.path = Path(out_dir) / MANIFEST_NAME
        self.outputs: dict[str, dict] = {}
        self.failed: dict[str, dict] = {}
        self.stats: dict[str, dict] = {}
        try:
            payload = parse_json(self.path.read_bytes(), SCHEMA, what="manifest")
            self.outputs = dict(payload.get("outputs", {}))
            self.failed = dict(payload.get("failed", {}))
            self.stats = dict(payload.get("stats", {}))
        except (OSError, InputError):
            pass  # no manifest yet, or one that is not ours (checked first): everything is made again
        self.root = Path(out_dir).resolve()

    def _key(self, output: Path) -> str:
        return output.relative_to(self.root).as_posix()

    def is_current(self, source: Path, name: str, output: Path, key: str) -> bool:
        """True if `output` was made from `source` with options `key` and is not older."""
        record = self.outputs.get(self._key(output))
        if not record or record.get("input") != name or record.get("key") != key:
            return False
        try:
            return output.stat().st_mtime_ns >= source.stat().st_mtime_ns
        except OSError:
            return False

    def earlier_failure(self, source: Path, name: str, key: str) -> str | None:
        """The error of an earlier run on this unchanged input with the same options, if any."""
        record = self.failed.get(name)
        try:
            if record and record.get("key") == key and tuple(record.get("stamp", ())) == _stamp(source):
                return record.get("error")
        except OSError:
            pass
        return None

    def made(self, name: str, output: Path, key: str) -> None:
        self.outputs[self._key(output)] = {"input": name, "key": key}
        self.failed.pop(name, None)

    def remember(self, name: str, stats: FileStats) -> None:
        """Keep the figures of `name`'s run (those it measured; earlier ones for the rest)."""
        figures = {field: value for field, value in dataclasses.asdict(stats).items() if value not in (None, ())}
        self.stats[name] = {**self.stats.get(name, {}), **figures}

    def stats_of(self, name: str) -> FileStats | None:
        """The figures of the run that made `name`'s outputs, if known."""
        known = {field.name for field in dataclasses.fields(FileStats)}
        figures = {k: tuple(v) if isinstance(v, list) else v for k, v in self.stats.get(name, {}).items()
                   if k in known}
        return FileStats(**figures) if figures else None

    def failure(self, source: Path, name: str, key: str, error: str) -> None:
        try:
            self.failed[name] = {"key": key, "stamp": list(_stamp(source)), "error": error}
        except OSError:
            pass  # the input went away: nothing to remember it by

    def save(self) -> None:
        payload = {"format": "onestroke-batch-manifest", "version": 1,
                   "outputs": dict(sorted(self.outputs.items())), "failed": dict(sorted(self.failed.items())),
                   "stats": dict(sorted(self.stats.items()))}
        atomic_write_text(self.path, json.dumps(payload, indent=1) + "\n")
