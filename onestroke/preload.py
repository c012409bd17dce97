"""Import what a later stage needs on a spare core while the earlier stages run.

A whole `onestroke vectorize` process spends most of its time importing libraries. The
fitting at the end needs scipy.interpolate (FITPACK, which brings scipy.optimize and
scipy.fft: about 0.1 s of CPU), the classification onnxruntime and its session; the
stages before them need neither. Started once the early stages' own imports are done (so the
two threads never import the same module at once), these imports run in a background
thread while outline, medial axis and pruning work, much of it in qhull and numpy loops
that let go of the GIL. The stage that needs them waits for the thread first.

Nothing changes in what is computed: an import that fails in the thread is simply done
again (and its error raised) where the stage imports the module itself.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable

_threads: dict[str, threading.Thread] = {}
_lock = threading.Lock()


def preload(name: str, modules: tuple[str, ...], then: Callable[[], object] | None = None) -> None:
    """Start importing `modules` (and then calling `then`, e.g. to open a model) in a daemon
    thread called `name`, once per process; a name already started or done is left alone."""
    with _lock:
        if name in _threads:
            return
        thread = threading.Thread(target=_load, args=(modules, then), name=f"preload {name}", daemon=True)
        _threads[name] = thread
    thread.start()


def wait(name: str) -> None:
    """Wait for the preload called `name`, if one was started."""
    thread = _threads.get(name)
    if thread is not None and thread is not threading.current_thread():
        thread.join()


def _load(modules: tuple[str, ...], then: Callable[[], object] | None) -> None:
    try:
        for module in modules:
            importlib.import_module(module)
        if then is not None:
            then()
    except Exception:  # noqa: BLE001 - the stage imports again and reports it
        pass
