"""Run a batch: skip what is current, hand the rest to workers, write what comes back.

Workers are this process (one job), local worker processes that survive a dead worker
(`pool.py`), or the workers of a Dask distributed cluster (`cluster.py`, input files sent as
bytes). In every case `process_file` makes the bytes and this process writes them: the
outputs of one drawing all at once or none (`onestroke.atomic.all_or_nothing`), then records
them in the manifest. An interrupted batch keeps every finished output, leaves no partial
file and picks up where it stopped. A batch that cannot go on (the disk is full or
read-only, the scheduler was lost) stops, writes its report saying why, and raises.
"""

from __future__ import annotations

import errno
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from fabrication.batch.inputs import BatchItem, Todo
from fabrication.batch.manifest import Manifest
from fabrication.batch.report import BatchSummary, FileRecord, ReportRoom, report_paths, write_report
from fabrication.batch.work import BatchJob, FileResult, process_file
from onestroke.atomic import all_or_nothing, atomic_write_bytes, make_folder
from onestroke.errors import OnestrokeError, OutputError
from onestroke.ranges import Range

# Worker processes of one batch (a pool of more than a thousand is a mistake, not a plan).
JOBS = Range(1, 1024, name="--jobs", integer=True)

# Seconds between manifest saves while results come in (and always at the end).
SAVE_EVERY = 2.0
# Write errors of the output folder as a whole: every next drawing would fail the same way,
# so the batch stops (a name too long, a folder in an output's place fail that drawing only).
STOPS_THE_BATCH = (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO, errno.EACCES, errno.EPERM)

def _in_process(todo: Todo, job: BatchJob) -> Iterator[tuple[BatchItem, FileResult]]:
    for item, needed in todo:
        yield item, process_file(item.name, job, path=str(item.source), extensions=needed)


def run_batch(items: list[BatchItem], job: BatchJob, out_dir: str | os.PathLike, *, jobs: int | None = None,
              scheduler: str | None = None, retry_failed: bool = False,
              on_start: Callable[[int, int, int], None] | None = None,
              on_file: Callable[[FileRecord], None] | None = None) -> BatchSummary:
    """Make every output of `items` that is not current; write the report and the manifest.

    jobs: worker processes (default: all cores; 1 runs here); scheduler: a Dask scheduler
    address (tcp://host:port) instead; retry_failed: try again inputs that failed before
    unchanged; on_start(to_make, skipped, failed_before) and on_file(record) report progress.
    A `KeyboardInterrupt` stops the batch after saving the report and the manifest; an
    `OnestrokeError` that stops it (disk full, scheduler lost) is raised again after that,
    its message extended with what was made and where the report is.
    """
    started = time.perf_counter()
    out = make_folder(out_dir)
    manifest = Manifest(out)
    room = ReportRoom(out, len(items), len(job.targets))
    records: dict[str, FileRecord] = {}
    todo: Todo = []
    keys: dict[str, str] = {}
    target_keys = {t.extension: job.key(t.extension) for t in job.targets}
    for item in items:
        needed = tuple(ext for ext, path in item.outputs
                       if not manifest.is_current(item.source, item.name, path, target_keys[ext]))
        outputs = tuple(path.relative_to(manifest.root).as_posix() for _, path in item.outputs)
        keys[item.name] = "+".join(target_keys[ext] for ext in needed)
        earlier = None if retry_failed or not needed else manifest.earlier_failure(
            item.source, item.name, keys[item.name])
        if not needed:
            records[item.name] = FileRecord(input=item.name, status="skipped", outputs=outputs,
                                            stats=manifest.stats_of(item.name))
        elif earlier is not None:
            records[item.name] = FileRecord(input=item.name, status="failed", error=f"{earlier} (earlier run)")
        else:
            todo.append((item, needed))
    if on_start:
        on_start(len(todo), sum(r.status == "skipped" for r in records.values()),
                 sum(r.status == "failed" for r in records.values()))

    workers = 0
    workers_seen: list[int] = []
    ran = 0
    stopped: OnestrokeError | None = None
    last_save = time.monotonic()
    results = None
    try:
        if scheduler:
            from fabrication.batch.cluster import run_cluster

            results = run_cluster(todo, job, scheduler, workers_seen)
        else:
            workers = min(jobs or os.cpu_count() or 1, len(todo))
            if workers <= 1:
                results = _in_process(todo, job)
            else:
                from fabrication.batch.pool import run_pool

                results = run_pool(todo, job, workers)
        for item, result in results:
            record = _store(item, result, target_keys, manifest, keys[item.name])
            records[item.name] = record
            ran += 1
            if on_file:
                on_file(record)
            if time.monotonic() - last_save > SAVE_EVERY:
                manifest.save()
                last_save = time.monotonic()
    except OnestrokeError as error:  # the batch cannot go on: keep what is made, say why
        stopped = error
    finally:
        if results is not None:
            results.close()  # stops the workers now if this ends early (Ctrl-C)
        reason = f"not run: {stopped}" if stopped is not None else None
        for item, _ in todo:
            records.setdefault(item.name, FileRecord(input=item.name, status="not run", error=reason))
        room.release()
        rows = list(records.values())
        csv_path, json_path = report_paths(out)
        summary = BatchSummary(
            total=len(rows), ran=ran, ok=sum(r.status == "ok" for r in rows),
            failed=sum(r.status == "failed" for r in rows), skipped=sum(r.status == "skipped" for r in rows),
            not_run=sum(r.status == "not run" for r in rows), seconds=time.perf_counter() - started,
            workers=workers_seen[-1] if workers_seen else workers, scheduler=scheduler,
            report_csv=str(csv_path), report_json=str(json_path),
            stopped=None if stopped is None else str(stopped))
        fields = {k: getattr(summary, k) for k in ("total", "ran", "ok", "failed", "skipped", "not_run", "seconds",
                                                   "workers", "scheduler", "stopped")}
        manifest.save()
        write_report(out, rows, {**fields, "per_second": summary.per_second})
    if stopped is not None:
        raise type(stopped)(f"{stopped}; the batch stopped: {summary.ok} made, {summary.not_run} not run (the "
                            f"same command goes on from there); report: {csv_path}") from None
    return summary


def _store(item: BatchItem, result: FileResult, target_keys: dict[str, str], manifest: Manifest,
           key: str) -> FileRecord:
    """Write one file's outputs, all or none, and record them; a write error fails that file,
    or, when it is the output folder's (STOPS_THE_BATCH), is raised to stop the batch."""
    error = result.error
    if error is None:
        try:
            with all_or_nothing():
                for extension, content in result.outputs:
                    path = item.output(extension)
                    make_folder(path.parent)
                    atomic_write_bytes(path, content)
        except OutputError as failure:
            if failure.errno in STOPS_THE_BATCH:
                raise
            error = str(failure)
        else:
            for extension, _ in result.outputs:
                manifest.made(item.name, item.output(extension), target_keys[extension])
            manifest.remember(item.name, result.stats)
    if error is not None and not result.worker_lost:
        manifest.failure(item.source, item.name, key, error)
    # every output of the input is current now: made in this run or found current
    outputs = () if error else tuple(path.relative_to(manifest.root).as_posix() for _, path in item.outputs)
    return FileRecord(input=item.name, status="failed" if error else "ok", outputs=outputs, stats=result.stats,
                      error=error)
