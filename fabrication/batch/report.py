"""The batch report: one row per input (CSV and JSON) and a summary."""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from onestroke.atomic import atomic_write_text, os_reason
from onestroke.errors import OutputError

REPORT_NAME = "onestroke-batch-report"
RESERVE_NAME = ".onestroke-batch-reserve"
COLUMNS = ("input", "status", "outputs", "strokes", "intersections", "warnings", "stitches",
           "sew_seconds", "laser_seconds", "seconds", "error")


@dataclass(frozen=True, kw_only=True)
class FileStats:
    """What one input gave: strokes / intersections (the vectorizer's counts), warnings,
    stitches and sew_seconds (machine time) of the first embroidery target, laser_seconds
    (estimated job time) of the first laser target, seconds (processing wall time)."""

    strokes: int | None = None
    intersections: int | None = None
    warnings: tuple[str, ...] = ()
    stitches: int | None = None
    sew_seconds: float | None = None
    laser_seconds: float | None = None
    seconds: float | None = None


@dataclass(frozen=True, kw_only=True)
class FileRecord:
    """One report row. status: "ok", "failed", "skipped" (outputs current) or "not run"
    (the batch was stopped first; error: why); outputs: paths relative to the output folder;
    stats: the figures of this run, or for a skipped input those of the run that made it."""

    input: str
    status: str
    outputs: tuple[str, ...] = ()
    stats: FileStats | None = None
    error: str | None = None

    def row(self) -> dict:
        """The flat row of the CSV and JSON report (keys: COLUMNS)."""
        stats = asdict(self.stats or FileStats())
        return {"input": self.input, "status": self.status, "outputs": self.outputs, **stats, "error": self.error}


@dataclass(frozen=True, kw_only=True)
class BatchSummary:
    """Counts and times of one run: total inputs, ran (processed in this run), ok, failed
    (in this run or unchanged since an earlier one), skipped (current), not_run (stopped
    first); workers: processes or Dask workers used (0: none needed); stopped: why the
    batch stopped before the end (None: it did not)."""

    total: int
    ran: int
    ok: int
    failed: int
    skipped: int
    not_run: int
    seconds: float
    workers: int
    scheduler: str | None
    report_csv: str
    report_json: str
    stopped: str | None = None

    @property
    def per_second(self) -> float:
        """Drawings processed per second of wall time (skipped ones not counted)."""
        return self.ran / self.seconds if self.seconds > 0 else 0.0


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, tuple):
        return "; ".join(value)
    if isinstance(value, float):
        return f"{value:.3f}"
    return str(value)


def report_paths(out_dir: str | os.PathLike) -> tuple[Path, Path]:
    folder = Path(out_dir)
    return folder / f"{REPORT_NAME}.csv", folder / f"{REPORT_NAME}.json"


def write_report(out_dir: str | os.PathLike, records: list[FileRecord], summary: dict) -> None:
    """Write the CSV (one row per input) and the JSON (summary and rows), atomically."""
    csv_path, json_path = report_paths(out_dir)
    rows = sorted(records, key=lambda r: r.input)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(COLUMNS)
    for record in rows:
        row = record.row()
        writer.writerow([_cell(row[column]) for column in COLUMNS])
    atomic_write_text(csv_path, buffer.getvalue())
    payload = {"summary": summary, "files": [r.row() for r in rows]}
    atomic_write_text(json_path, json.dumps(payload, indent=1) + "\n")


class ReportRoom:
    """Room on the disk held for the report and the manifest while a batch runs: a file of
    their likely size (`posix_fallocate`), removed just before they are written, so that a
    disk filled by the outputs still takes the report that says so.

    `OutputError` if the room is not there at the start (nothing has been made yet).
    """

    def __init__(self, out_dir: str | os.PathLike, inputs: int, targets: int) -> None:
        self.path = Path(out_dir) / RESERVE_NAME
        # measured: 20 inputs to svg, pes and gcode wrote a 10.6 kB manifest, a 3.1 kB CSV and an
        # 8.2 kB JSON (1.1 kB per input); about twice that, for long names and error messages
        size = 8192 + inputs * (2048 + 256 * targets)
        try:
            fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            try:
                if hasattr(os, "posix_fallocate"):
                    os.posix_fallocate(fd, 0, size)
                else:  # macOS, Windows: written out
                    os.write(fd, bytes(size))
            finally:
                os.close(fd)
        except OSError as error:
            self.release()
            raise OutputError(f"cannot keep {size / 1024:.0f} kB for the batch's report in {str(out_dir)!r}: "
                              f"{os_reason(error)}", errno=error.errno) from None

    def release(self) -> None:
        try:
            os.unlink(self.path)
        except OSError:
            pass
