"""Libraries loaded for good: imported with the cyclic garbage collector paused, and what is
alive then left out of its passes (`gc.freeze`).

A library's import makes thousands of objects that stay until the process ends and next to
no garbage, yet its allocations set off collections that go through every object made so
far, and every later collection goes through its objects again. A short command loads the
libraries of its work this way before the work (`fabrication.cli.heap.loading_for_good`).
Some are imported only where a drawing needs them, in the middle of the work: onnxruntime
for a drawing with crossings, networkx for a route with more than two odd nodes. Those
are imported through `import_later`, which loads them the same way once the process has asked for
it (`load_later_imports_for_good`), and imports them plainly otherwise: a long-running process
(the studio) keeps the collector as it is, since a frozen garbage cycle is never freed.
"""

from __future__ import annotations

import gc
import importlib
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

_for_good = False  # set by a short command (`load_later_imports_for_good`)


def load_later_imports_for_good() -> None:
    """From now on in this process, `import_later` loads what it imports for good."""
    global _for_good
    _for_good = True


@contextmanager
def paused_then_frozen() -> Iterator[None]:
    """The collector paused inside; everything alive at the end left out of its passes."""
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_on:
            gc.enable()


def import_later(name: str) -> ModuleType:
    """`importlib.import_module(name)`, for a library imported in the middle of the work: its
    first import is loaded for good (`paused_then_frozen`) where the process asked for it
    (`load_later_imports_for_good`). In a command that vectorizes a drawing needing
    networkx, the collections during and after its import took 8-11 ms of CPU, 1.1-1.9 ms
    with it (two drawings, three runs each, 2026-12-06)."""
    module = sys.modules.get(name)
    if module is not None:  # loaded already: nothing to freeze again
        return module
    if not _for_good:
        return importlib.import_module(name)
    with paused_then_frozen():
        return importlib.import_module(name)
