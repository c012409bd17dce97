"""Run a batch: skip what is current, hand the rest to workers, write what comes back.

Workers are this process (one job), a `concurrent.futures` process pool (N jobs, each worker
loads the imports and the model once), or the workers of a Dask distributed cluster (input
files sent as bytes). In every case `process_file` makes the bytes and this process writes
them, atomically, then records them in the manifest: an interrupted batch keeps every
finished output, leaves no partial file and picks up where it stopped.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from fabrication.batch.inputs import BatchItem
from fabrication.batch.manifest import Manifest
from fabrication.batch.report import BatchSummary, FileRecord, report_paths, write_report
from fabrication.batch.work import BatchJob, FileResult, process_file, warm_up
from onestroke.atomic import atomic_write_bytes
from onestroke.errors import FabricationError, InputError
from onestroke.ranges import Range

# Worker processes of one batch (a pool of more than a thousand is a mistake, not a plan).
JOBS = Range(1, 1024, name="--jobs", integer=True)

# Seconds between manifest saves while results come in (and always at the end).
SAVE_EVERY = 2.0
# Files handed to a Dask cluster ahead of the results, per worker: keeps workers busy
# without holding every input's bytes in memory at once.
DASK_AHEAD = 4

Todo = list[tuple[BatchItem, tuple[str, ...]]]


def _in_process(todo: Todo, job: BatchJob) -> Iterator[tuple[BatchItem, FileResult]]:
    for item, needed in todo:
        yield item, process_file(item.name, job, path=str(item.source), extensions=needed)


@contextlib.contextmanager
def _interrupts_ignored() -> Iterator[None]:
    """SIGINT ignored in this block (in the main thread; elsewhere signals cannot be set)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _process_pool(todo: Todo, job: BatchJob, workers: int) -> Iterator[tuple[BatchItem, FileResult]]:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # spawn: fresh interpreters (no locks or threads of this process copied into them),
    # started with Ctrl-C ignored (kept across exec): a worker interrupted while it imports
    # would print a traceback; the client alone handles Ctrl-C
    with _interrupts_ignored():
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=warm_up, initargs=(job,))
        futures = {pool.submit(process_file, item.name, job, path=str(item.source), extensions=needed): item
                   for item, needed in todo}
    try:
        for future in as_completed(futures):
            item = futures[future]
            try:
                result = future.result()
            except Exception as error:  # a worker died (out of memory, killed): this file failed
                result = FileResult(name=item.name, error=f"worker failed: {type(error).__name__}: {error}")
            yield item, result
    except BaseException:  # Ctrl-C, or the caller stopped early: no worker holds anything to keep
        # (a private attribute; Python 3.14 has ProcessPoolExecutor.terminate_workers for this)
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.terminate()
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _dask(todo: Todo, job: BatchJob, address: str, workers_seen: list) -> Iterator[tuple[BatchItem, FileResult]]:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise InputError("a Dask scheduler needs the dask extra: pip install 'onestroke[dask]'") from None
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as error:
        raise FabricationError(f"cannot reach the Dask scheduler at {address!r}: {error}") from None
    with client:
        workers_seen.append(len(client.scheduler_info().get("workers", {})))
        client.run(warm_up, job, ignore_interrupt=False)
        queue = iter(todo)
        pending: dict = {}
        running = as_completed()

        def hand_out() -> Iterator[tuple[BatchItem, FileResult]]:
            """Submit the next file that can be read; yield the ones that cannot."""
            for item, needed in queue:
                try:
                    data = item.source.read_bytes()
                except OSError as error:
                    yield item, FileResult(name=item.name, error=f"cannot read {item.name!r}: {error.strerror}")
                    continue
                future = client.submit(process_file, item.name, job, data=data, extensions=needed, pure=False)
                pending[future] = item
                running.add(future)
                return

        try:
            for _ in range(max(1, workers_seen[-1]) * DASK_AHEAD):
                yield from hand_out()
            for future in running:
                item = pending.pop(future)
                try:
                    result = future.result()
                except Exception as error:  # the worker was lost
                    result = FileResult(name=item.name, error=f"worker failed: {type(error).__name__}: {error}")
                yield item, result
                yield from hand_out()
        finally:
            client.cancel(list(pending))


def run_batch(items: list[BatchItem], job: BatchJob, out_dir: str | os.PathLike, *, jobs: int | None = None,
              scheduler: str | None = None, retry_failed: bool = False,
              on_start: Callable[[int, int, int], None] | None = None,
              on_file: Callable[[FileRecord], None] | None = None) -> BatchSummary:
    """Make every output of `items` that is not current; write the report and the manifest.

    jobs: worker processes (default: all cores; 1 runs here); scheduler: a Dask scheduler
    address (tcp://host:port) instead; retry_failed: try again inputs that failed before
    unchanged; on_start(to_make, skipped, failed_before) and on_file(record) report progress.
    A `KeyboardInterrupt` stops the batch after saving the report and the manifest.
    """
    started = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    manifest = Manifest(out)
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
            records[item.name] = FileRecord(input=item.name, status="skipped", outputs=outputs)
        elif earlier is not None:
            records[item.name] = FileRecord(input=item.name, status="failed", error=f"{earlier} (earlier run)")
        else:
            todo.append((item, needed))
    if on_start:
        on_start(len(todo), sum(r.status == "skipped" for r in records.values()),
                 sum(r.status == "failed" for r in records.values()))

    workers = 0
    workers_seen: list[int] = []
    last_save = time.monotonic()
    results = None
    try:
        if scheduler:
            results = _dask(todo, job, scheduler, workers_seen)
        else:
            workers = min(jobs or os.cpu_count() or 1, len(todo))
            results = _in_process(todo, job) if workers <= 1 else _process_pool(todo, job, workers)
        for item, result in results:
            record = _store(item, result, target_keys, manifest, keys[item.name])
            records[item.name] = record
            if on_file:
                on_file(record)
            if time.monotonic() - last_save > SAVE_EVERY:
                manifest.save()
                last_save = time.monotonic()
    finally:
        if results is not None:
            results.close()  # stops the workers now if this ends early (Ctrl-C)
        for item, _ in todo:
            records.setdefault(item.name, FileRecord(input=item.name, status="not run"))
        manifest.save()
        rows = list(records.values())
        csv_path, json_path = report_paths(out)
        summary = BatchSummary(
            total=len(rows), ran=sum(r.stats is not None for r in rows), ok=sum(r.status == "ok" for r in rows),
            failed=sum(r.status == "failed" for r in rows), skipped=sum(r.status == "skipped" for r in rows), not_run=sum(r.status == "not run" for r in rows),
            seconds=time.perf_counter() - started, workers=workers_seen[-1] if workers_seen else workers,
            scheduler=scheduler, report_csv=str(csv_path), report_json=str(json_path))
        fields = {k: getattr(summary, k) for k in ("total", "ran", "ok", "failed", "skipped", "not_run", "seconds",
                                                   "workers", "scheduler")}
        write_report(out, rows, {**fields, "per_second": summary.per_second})
    return summary


def _store(item: BatchItem, result: FileResult, target_keys: dict[str, str], manifest: Manifest,
           key: str) -> FileRecord:
    """Write one file's outputs (atomically) and record them; a write error fails that file."""
    error = result.error
    if error is None:
        try:
            for extension, content in result.outputs:
                path = item.output(extension)
                path.parent.mkdir(parents=True, exist_ok=True)
                atomic_write_bytes(path, content)
                manifest.made(item.name, path, target_keys[extension])
        except OSError as failure:
            error = f"cannot write {str(failure.filename or item.name)!r}: {failure.strerror}"
    if error is not None:
        manifest.failure(item.source, item.name, key, error)
    # every output of the input is current now: made in this run or found current
    outputs = () if error else tuple(path.relative_to(manifest.root).as_posix() for _, path in item.outputs)
    return FileRecord(input=item.name, status="failed" if error else "ok", outputs=outputs, stats=result.stats,
                      error=error)
