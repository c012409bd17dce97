"""Processes as Linux's /proc shows them: children, liveness, CPU time (for fault tests and
the fault-case runner, which kill workers and parents and look for what is left)."""

from __future__ import annotations

import os
from pathlib import Path


def _stat_fields(pid: int) -> list[str] | None:
    """The fields of /proc/PID/stat after the command name (state first), or None if gone."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return stat[stat.rindex(")") + 2:].split()


def alive(pid: int) -> bool:
    """True while `pid` runs (a zombie waiting for its parent counts as ended)."""
    fields = _stat_fields(pid)
    return fields is not None and fields[0] != "Z"


def children(pid: int) -> list[int]:
    """Processes whose parent is `pid`."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            fields = _stat_fields(int(entry))
            if fields is not None and int(fields[1]) == pid:
                found.append(int(entry))
    return found


def cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def workers_of(pid: int) -> list[int]:
    """A batch's worker interpreters (multiprocessing spawn) among `pid`'s children; not
    multiprocessing's resource tracker."""
    return [child for child in children(pid) if "spawn_main" in cmdline(child)]


def cpu_ticks(pid: int) -> int:
    """User + system clock ticks `pid` has used (-1 once it is gone)."""
    fields = _stat_fields(pid)
    return -1 if fields is None else int(fields[11]) + int(fields[12])


def rss_mb(pids: list[int]) -> float:
    """Resident memory of `pids` together, MB (those still there)."""
    total = 0
    for pid in pids:
        try:
            total += int(Path(f"/proc/{pid}/status").read_text().split("VmRSS:")[1].split()[0])
        except (OSError, IndexError):
            pass
    return total / 1024


def state(pid: int) -> str:
    """The scheduler state of `pid`'s main thread: "R" running, "S" sleeping (an idle worker
    waiting for work), "Z" a zombie...; "" once it is gone."""
    fields = _stat_fields(pid)
    return "" if fields is None else fields[0]


def child_cpu_seconds() -> float:
    """User + sys seconds of this process's finished children so far (all their threads)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime
