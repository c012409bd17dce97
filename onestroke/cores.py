"""How many threads a stage may spread its work over (qhull, scipy.ndimage's labelling and
filters and numpy's big loops let go of the GIL while they work)."""

from __future__ import annotations

import os


def idle_cores() -> int:
    """The process's cores while the machine has one to spare (1-minute load average below
    cores - 0.5), else 1: on a busy machine threads wait for the same cores and only add
    their overhead (the results are the same either way)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    busy = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    return cores if busy < cores - 0.5 else 1
