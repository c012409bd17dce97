"""Heap settings for a short command: glibc's, for large arrays allocated and freed, and
the garbage collector's, for the libraries loaded before the work (`freeze_loaded_objects`).

A vectorization allocates and frees whole-image arrays (4-8 MB for a 1000 px image) dozens of
times. With glibc's defaults an array that large is mapped afresh and unmapped again, or the
heap top holding it is given back to the system when it is freed, so each new one touches
new pages: a `vectorize_image` call took ~12,000 minor page faults as a process's first call
and 1,000-4,000 afterwards, ~2 microseconds each on this machine. Serving such arrays from the
heap (the mmap threshold raised to 32 MB) and keeping freed heap memory for the next array
(the trim threshold raised to 1 GB) halves the first call's faults (15 drawings, 2026-12-05:
~6,000) and takes the later calls' to nearly none. The memory stays with the process until it
ends, which a command does a second later; a long-running process (the studio) keeps
glibc's defaults.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from onestroke.lasting import paused_then_frozen

if TYPE_CHECKING:
    import threading

# mallopt's parameter numbers (glibc's malloc.h)
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
M_ARENA_MAX = -8
MMAP_THRESHOLD = 32 << 20  # glibc's largest accepted value on 64-bit systems
TRIM_THRESHOLD = 1 << 30


def keep_freed_memory() -> bool:
    """Raise glibc's mmap and trim thresholds for this process (module doc), and keep every
    thread's allocations in the one heap (one arena). Call it before the process starts a
    thread: a second thread otherwise gets an arena of its own, and what it frees (the
    binarize stage's arrays, made on a spare core while the libraries load,
    `vectorize.pipeline.binarize_beside`) stays there, out of reach of the stages after it.
    Set before the image is read instead of after the imports, with one arena: a command's
    minor page faults ~28,000 -> ~21,500 (the 15 drawings of `startup_cost.py --pairs`, 4
    rounds, 2026-12-06; the work's own ~4,400-4,800 -> ~2,000-2,600 on three of four checked,
    8,400 -> 6,200 on the fourth).
    Returns whether all were set: False where the C library has no `mallopt` (macOS, musl,
    Windows)."""
    try:
        import ctypes  # already loaded by numpy

        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError, TypeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    return all([bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)), bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD)),
                bool(mallopt(M_ARENA_MAX, 1))])


# The heap made ready beside a command's imports (`touch_heap_beside`): under glibc's mmap
# threshold, so it comes from the heap; more than the imports' and the binarize stage's
# allocations take of it (~12 MB and ~14 MB of pages, the 15 drawings of `startup_cost.py
# --pairs`), which then fault no page in.
HEAP_AHEAD = 24 << 20


def touch_heap_beside(size: int = HEAP_AHEAD) -> threading.Thread | None:
    """Grow the heap by `size` bytes in a second thread, touch every page of it and free it
    again (kept by `keep_freed_memory`, which must be set first): the page faults of the
    first use, ~2 microseconds a page on this machine, are paid there instead of in the
    main thread's imports (~3,100 faults fewer) and the binarize stage (~3,500 fewer). For a
    command with a core to spare; the C library's malloc, memset and free through ctypes,
    which let go of the GIL. Returns the thread, or None where the C library has no such
    functions."""
    import threading

    try:
        import ctypes

        libc = ctypes.CDLL(None)
        malloc, free = libc.malloc, libc.free
    except (OSError, AttributeError, TypeError):
        return None
    malloc.restype, malloc.argtypes = ctypes.c_void_p, (ctypes.c_size_t,)
    free.restype, free.argtypes = None, (ctypes.c_void_p,)

    def touched() -> None:
        block = malloc(size)
        if block:
            ctypes.memset(block, 0, size)
            free(block)

    thread = threading.Thread(target=touched, name="heap ahead", daemon=True)
    thread.start()
    return thread


def freeze_loaded_objects() -> None:
    """Leave every object alive now (the modules, classes and functions of the libraries
    just imported, ~53,000 on a raster drawing) out of the cyclic garbage collector's passes
    for the rest of the process (`gc.freeze`). A command never frees them, and the
    collections that its own allocations set off went through them again and again: the
    whole `onestroke vectorize` process took 1.000 -> 0.875 s of CPU (median of 30 runs,
    the 15 drawings of `startup_cost.py --pairs 15` twice, load 6-7, 2026-12-05), the same
    SVG bytes. Garbage cycles alive at this moment stay until the process ends."""
    gc.freeze()


@contextmanager
def loading_for_good() -> Iterator[None]:
    """Imports inside run with the cyclic garbage collector paused, and everything alive at
    the end is left out of its passes (`onestroke.lasting.paused_then_frozen`). A library's
    import makes thousands of objects that stay and next to no garbage, yet its allocations set off
    collections that go through all the objects made so far: pausing the collector while
    scipy, scikit-image and the stages load (the bare import floor of `startup_cost.py
    --pairs` imports them with it running) took the garbage collection in a command from
    75-120 to 10-30 ms (3 drawings, gc callbacks) and the command / floor ratio from 1.181
    to 1.105 wall, 1.167 to 1.128 CPU (median of 45 pairs, load 7, 2026-12-05)."""
    with paused_then_frozen():
        yield
