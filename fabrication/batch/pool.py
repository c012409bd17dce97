"""Local worker processes for a batch, that survive a dead worker.

`concurrent.futures.ProcessPoolExecutor` cannot tell which task a dead worker was running:
one worker killed (the out-of-memory killer, a crash in a native library) breaks the whole
pool and fails every pending drawing with `BrokenProcessPool`. So each worker here is a
pool of one process, given one drawing at a time: when it dies, only the drawing it was
making is affected; that pool is replaced by a fresh one and the drawing is tried once more.
A drawing whose worker dies twice is failed as `worker_lost` (not the input's fault: a plain
rerun tries it again). Workers end with the batch process, however it ends
(`work.die_with_parent`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import signal
import threading
from collections import deque
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from fabrication.batch.inputs import BatchItem, Todo
from fabrication.batch.work import BatchJob, FileResult, process_file, warm_up

# Times a drawing is tried again after its worker process died while making it.
RETRIES = 1
RETRIED = "its worker process died while making it (killed, or out of memory); made again in a fresh one"

@contextlib.contextmanager
def _interrupts_ignored() -> Iterator[None]:
    """SIGINT ignored in this block (in the main thread; elsewhere signals cannot be set):
    spawned workers start with it ignored (kept across exec), so a worker interrupted while
    it imports prints no traceback; the batch process alone handles Ctrl-C."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _worker(job: BatchJob) -> ProcessPoolExecutor:
    """A pool of one fresh interpreter (spawn: no locks or threads of this process copied
    into it) that loads the pipeline once and ends with this process."""
    import functools
    import multiprocessing

    return ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"),
                               initializer=functools.partial(warm_up, parent=os.getpid()), initargs=(job,))


def _kill(worker: ProcessPoolExecutor) -> None:
    """End a worker's process now (its drawing is dropped)."""
    # a private attribute; Python 3.14 has ProcessPoolExecutor.terminate_workers for this
    for process in list((getattr(worker, "_processes", None) or {}).values()):
        with contextlib.suppress(OSError):
            process.kill()


def run_pool(todo: Todo, job: BatchJob, workers: int) -> Iterator[tuple[BatchItem, FileResult]]:
    """Make `todo` on `workers` processes; yields (item, result) as each drawing is done."""
    queue = deque(todo)
    deaths: dict[str, int] = {}
    with _interrupts_ignored():
        pool = [_worker(job) for _ in range(workers)]
    running: dict[Future, tuple[int, BatchItem, tuple[str, ...]]] = {}

    def hand_out(slot: int) -> None:
        if queue:
            item, needed = queue.popleft()
            # Only the submit that starts the worker's process ignores Ctrl-C (the process
            # inherits that): an ignored Ctrl-C is lost, and the later submits come right
            # after a drawing is written, when a user is most likely to press it.
            starting = not getattr(pool[slot], "_processes", None)  # private, as in _kill
            with _interrupts_ignored() if starting else contextlib.nullcontext():
                future = pool[slot].submit(process_file, item.name, job, path=str(item.source), extensions=needed)
            running[future] = (slot, item, needed)

    try:
        for slot in range(workers):
            hand_out(slot)
        while running:
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                slot, item, needed = running.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool:  # this worker died: replace it, try its drawing again
                    pool[slot].shutdown(wait=True)
                    with _interrupts_ignored():
                        pool[slot] = _worker(job)
                    deaths[item.name] = deaths.get(item.name, 0) + 1
                    if deaths[item.name] <= RETRIES:
                        queue.appendleft((item, needed))
                        hand_out(slot)
                        continue
                    result = FileResult(name=item.name, worker_lost=True,
                                        error=f"its worker process died {deaths[item.name]} times while making it "
                                              "(killed, or out of memory); a rerun tries it again")
                except Exception as error:  # noqa: BLE001 - e.g. a result that cannot be sent back
                    result = FileResult(name=item.name, error=" ".join(f"worker failed: {type(error).__name__}: "
                                                                       f"{error}".split()))
                else:
                    if deaths.get(item.name):
                        result = dataclasses.replace(result, stats=dataclasses.replace(
                            result.stats, warnings=result.stats.warnings + (RETRIED,)))
                yield item, result
                hand_out(slot)
    except BaseException:  # Ctrl-C, a signal, or the caller stopped: no worker holds anything to keep
        for worker in pool:
            _kill(worker)
        raise
    finally:
        for worker in pool:
            worker.shutdown(wait=True, cancel_futures=True)
