"""A batch on a Dask distributed cluster: the scheduler found and named, a lost one survived.

Before anything starts, `require_dask` says whether the dask extra is installed and
`probe_scheduler` looks at the address: nothing listening, a server that answers with
something else (an HTTP server, an SSH banner) or a silent one is named in one line within
a few seconds, instead of waiting on a Dask handshake that never comes. While the batch
runs, a lost scheduler stops it with `SchedulerLost`: the drawings not finished are left
unrecorded, so that running the same command again makes them.
"""

from __future__ import annotations

import contextlib
import socket
from collections.abc import Iterator

from fabrication.batch.inputs import BatchItem, Todo
from fabrication.batch.work import BatchJob, FileResult, process_file, warm_up
from onestroke.errors import FabricationError, InputError

# Seconds to connect, and to wait for a scheduler's greeting (it sends one at once).
CONNECT_SECONDS = 5.0
GREETING_SECONDS = 3.0
# Seconds the Dask client may take to connect, and to wait for a first worker.
CLIENT_SECONDS = 10.0
WORKER_SECONDS = 30.0
# Files handed to the cluster ahead of the results, per worker: keeps workers busy
# without holding every input's bytes in memory at once.
DASK_AHEAD = 4

class SchedulerLost(FabricationError):
    """The connection to the Dask scheduler broke while drawings were being made."""


def require_dask() -> None:
    """`InputError` unless the dask extra (distributed) can be imported."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise InputError("--scheduler needs the dask extra: pip install 'onestroke[dask]' (on this machine "
                         "and on every worker)") from None


def _host_port(address: str) -> tuple[str, str, int] | None:
    """(scheme, host, port) of a tcp:// or tls:// address; None for other schemes."""
    scheme, _, rest = address.partition("://")
    if scheme not in ("tcp", "tls"):
        return None
    host, colon, port = rest.rstrip("/").rpartition(":")
    if not colon or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"--scheduler {address!r} needs a port, e.g. tcp://10.0.0.5:8786")
    return scheme, host.strip("[]"), int(port)


def _is_dask_greeting(data: bytes) -> bool:
    """A Dask comm's handshake: a msgpack map with its python version and pickle protocol."""
    return b"pickle-protocol" in data and b"python" in data


def probe_scheduler(address: str) -> None:
    """Raise `FabricationError` naming what is at `address` unless it greets as a Dask scheduler.

    Bounded by CONNECT_SECONDS + 2 x GREETING_SECONDS. tls:// addresses are only connected
    to (their greeting is encrypted); other schemes (inproc://, ucx://) are left to Dask.
    """
    parts = _host_port(address)
    if parts is None:
        return
    scheme, host, port = parts
    try:
        connection = socket.create_connection((host, port), timeout=CONNECT_SECONDS)
    except socket.gaierror:
        raise FabricationError(f"--scheduler {address}: no host named {host!r}") from None
    except ConnectionRefusedError:
        raise FabricationError(f"--scheduler {address}: nothing is listening there (connection refused); start a "
                               "scheduler with `dask scheduler` (port 8786 by default)") from None
    except TimeoutError:
        raise FabricationError(f"--scheduler {address}: no answer within {CONNECT_SECONDS:g} s (a wrong host, "
                               "or a firewall)") from None
    except OSError as error:
        raise FabricationError(f"--scheduler {address}: cannot connect: {error.strerror or error}") from None
    with connection:
        if scheme == "tls":
            return
        connection.settimeout(GREETING_SECONDS)
        try:
            data = connection.recv(4096)
        except TimeoutError:
            data = None
        except OSError as error:
            raise FabricationError(f"--scheduler {address}: the connection failed: "
                                   f"{error.strerror or error}") from None
        if data is not None and _is_dask_greeting(data):
            return
        if data == b"":
            raise FabricationError(f"--scheduler {address}: the server there closed the connection at once; "
                                   "not a Dask scheduler")
        if data:
            banner = data.split(b"\n")[0].strip().decode("ascii", "replace")[:80]
            raise FabricationError(f"--scheduler {address}: a server there answered {banner!r}; not a Dask "
                                   "scheduler")
        # silent: a server that waits for its client to speak first, as HTTP does
        reply = b""
        with contextlib.suppress(OSError):
            connection.sendall(f"HEAD / HTTP/1.0\r\nHost: {host}\r\n\r\n".encode("ascii"))
            reply = connection.recv(4096)
        if reply.startswith(b"HTTP/"):
            status = reply.split(b"\r\n")[0].decode("ascii", "replace")[:60]
            raise FabricationError(f"--scheduler {address}: an HTTP server is there ({status}), not a Dask "
                                   "scheduler; the scheduler listens on port 8786 by default, its dashboard "
                                   "on 8787")
        raise FabricationError(f"--scheduler {address}: the server there sent nothing within "
                               f"{GREETING_SECONDS:g} s; not a Dask scheduler (which greets at once)")


def _lost(client) -> bool:
    return client.status not in ("running", "newly-created")


def run_cluster(todo: Todo, job: BatchJob, address: str, workers_seen: list) -> Iterator[tuple[BatchItem, FileResult]]:
    """Make `todo` on the cluster at `address`; yields (item, result) as each drawing is done.

    workers_seen gets the number of workers. Raises `SchedulerLost` when the scheduler goes
    away: what was not yielded yet is left for a rerun.
    """
    from distributed import Client, as_completed

    probe_scheduler(address)
    try:
        client = Client(address, timeout=f"{CLIENT_SECONDS:g}s")
    except (OSError, TimeoutError, ValueError) as error:
        raise FabricationError(f"--scheduler {address}: the Dask client could not connect: "
                               f"{' '.join(str(error).split())}") from None
    pending: dict = {}
    try:
        try:
            client.wait_for_workers(1, timeout=WORKER_SECONDS)
        except TimeoutError:
            raise FabricationError(f"--scheduler {address}: the scheduler has no workers (waited "
                                   f"{WORKER_SECONDS:g} s); start some with `dask worker {address} "
                                   "--nthreads 1`") from None
        workers_seen.append(len(client.scheduler_info().get("workers", {})))
        client.run(warm_up, job, ignore_interrupt=False)
        queue = iter(todo)
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

        for _ in range(max(1, workers_seen[-1]) * DASK_AHEAD):
            yield from hand_out()
        for future in running:
            item = pending.pop(future)
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001 - the scheduler, or this drawing's worker, was lost
                if _lost(client) or type(error).__name__ in ("FutureCancelledError", "CancelledError"):
                    raise SchedulerLost(f"lost the Dask scheduler at {address}: the connection closed") from None
                result = FileResult(name=item.name, worker_lost=type(error).__name__ == "KilledWorker",
                                    error=" ".join(f"worker failed: {type(error).__name__}: {error}".split()))
            yield item, result
            yield from hand_out()
    except (OSError, TimeoutError) as error:  # the connection broke outside a result
        if _lost(client):
            raise SchedulerLost(f"lost the Dask scheduler at {address}: {type(error).__name__}") from None
        raise
    finally:
        if not _lost(client):
            with contextlib.suppress(Exception):
                client.cancel(list(pending))
        with contextlib.suppress(Exception):
            client.close(timeout=5)
