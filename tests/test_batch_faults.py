"""Faults for real (issue 28): a worker killed mid-batch, the batch's own process killed, a
Dask scheduler killed mid-run, a disk that fills up, addresses where no scheduler is.

Processes are killed with real signals, found through /proc; full disks are tiny tmpfs
mounts in a private mount namespace (fault_fixtures). Every run's outputs are compared
with the bytes of one undisturbed run of the same drawings.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from benchmarks.sets.batch_drawings import make_drawing_folder
from benchmarks.common.processes import alive, children, state, workers_of
from fabrication.batch.pool import RETRIED
from fabrication.cli import main
from fault_fixtures import child_env, run_with_mounts, tmpfs

pytestmark = pytest.mark.slow

REPORT = "onestroke-batch-report"
LOOPS = Path(__file__).resolve().parents[1] / "examples" / "loops.png"


def read_report(out: Path) -> dict[str, dict]:
    with open(out / f"{REPORT}.csv", newline="", encoding="utf-8") as handle:
        return {row["input"]: row for row in csv.DictReader(handle)}


def outputs_of(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and not p.name.startswith(("onestroke-batch-", "."))}


def wait_for(condition, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return False


@pytest.fixture(scope="module")
def drawings(tmp_path_factory):
    """Six drawings and their outputs made by one undisturbed in-process run."""
    root = tmp_path_factory.mktemp("faults")
    make_drawing_folder(root / "in", corrupt=False, count=6)
    reference = root / "reference"
    result = CliRunner().invoke(main, ["batch", str(root / "in"), "-o", str(reference), "--to", "svg,pes",
                                       "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return root / "in", outputs_of(reference), read_report(reference)


def batch_process(*args, **kwargs) -> subprocess.Popen:
    """`onestroke batch ...` as its own process; output to files (a worker left behind would
    hold a pipe open)."""
    return subprocess.Popen([sys.executable, "-m", "fabrication.cli", "batch", *map(str, args)],
                            stdout=subprocess.DEVNULL, stderr=kwargs.pop("stderr", subprocess.DEVNULL),
                            env=child_env(), **kwargs)


def test_a_worker_killed_mid_batch_costs_one_retry(drawings, tmp_path):
    folder, reference, first = drawings
    out = tmp_path / "out"
    process = batch_process(folder, "-o", out, "--to", "svg,pes", "--jobs", "2")
    killed = None
    try:
        # a worker running a drawing (state R: not waiting for one), once the pool has warmed up
        def busy() -> bool:
            nonlocal killed
            if process.poll() is not None or not list(out.rglob("*.svg")):
                return process.poll() is not None
            running = [w for w in workers_of(process.pid) if state(w) == "R"]
            if running:
                os.kill(running[0], signal.SIGKILL)  # as the out-of-memory killer does
                killed = running[0]
            return killed is not None
        assert wait_for(busy, 300) and killed is not None, "the batch ended before a worker could be killed"
        assert process.wait(timeout=300) == 0
    finally:
        process.kill()
    report = read_report(out)
    assert {row["status"] for row in report.values()} == {"ok"} and len(report) == 6
    assert sum(RETRIED in row["warnings"] for row in report.values()) == 1
    assert outputs_of(out) == reference
    assert not [p for p in out.rglob("*") if p.name.endswith(".part")]
    # a plain rerun: everything current, each row with the figures of the run that made it
    rerun = CliRunner().invoke(main, ["batch", str(folder), "-o", str(out), "--to", "svg,pes", "--jobs", "2"])
    assert rerun.exit_code == 0 and "6 of 6 drawings are current" in rerun.output
    again = read_report(out)
    for name, row in again.items():
        assert row["status"] == "skipped"
        assert (row["strokes"], row["stitches"], row["sew_seconds"]) == \
            (first[name]["strokes"], first[name]["stitches"], first[name]["sew_seconds"])
        assert row["seconds"] == report[name]["seconds"] != ""


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM])
def test_the_batch_killed_leaves_no_process_after_5_s(drawings, tmp_path, signum):
    folder, reference, _ = drawings
    out = tmp_path / "out"
    process = batch_process(folder, "-o", out, "--to", "svg", "--jobs", "2", stderr=subprocess.PIPE)
    try:
        assert wait_for(lambda: len(workers_of(process.pid)) == 2 or process.poll() is not None, 300)
        assert process.poll() is None, "the batch ended before it could be killed"
        family = children(process.pid)  # the workers and multiprocessing's resource tracker
        process.send_signal(signum)
        _, err = process.communicate(timeout=60)
        ended = wait_for(lambda: not any(alive(pid) for pid in family), 5.0)
        assert ended, [pid for pid in family if alive(pid)]
    finally:
        process.kill()
    if signum == signal.SIGTERM:  # stopped as Ctrl-C stops it: report written, finished outputs kept
        assert process.returncode == 130 and b"interrupted (SIGTERM)" in err, err
        report = read_report(out)
        assert {row["status"] for row in report.values()} <= {"ok", "not run"} and len(report) == 6
        made = outputs_of(out)
        assert all(reference[name] == content for name, content in made.items())


def _local_cluster() -> tuple[subprocess.Popen, str]:
    """A LocalCluster (scheduler and one worker, threads of one process) in its own process."""
    code = ("import logging, time\nlogging.disable(logging.CRITICAL)\nfrom distributed import LocalCluster\n"
            "c = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol='tcp://', "
            "dashboard_address=None)\nprint(c.scheduler_address, flush=True)\ntime.sleep(3600)\n")
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               text=True, env=child_env())
    return process, process.stdout.readline().strip()


def test_a_scheduler_killed_mid_run_leaves_the_rest_to_a_rerun(drawings, tmp_path):
    folder, reference, _ = drawings
    out = tmp_path / "out"
    cluster, address = _local_cluster()
    try:
        process = batch_process(folder, "-o", out, "--to", "svg,pes", "--scheduler", address,
                                stderr=subprocess.PIPE)
        assert wait_for(lambda: list(out.rglob("*.pes")) or process.poll() is not None, 300)
        cluster.kill()
        _, err = process.communicate(timeout=120)
    finally:
        cluster.kill()
        cluster.wait()
    lines = err.decode().strip().splitlines()
    assert process.returncode == 1 and len(lines) == 1, err
    assert lines[0].startswith(f"error: lost the Dask scheduler at {address}") and "not run" in lines[0]
    report = read_report(out)
    statuses = [row["status"] for row in report.values()]
    assert set(statuses) == {"ok", "not run"}, statuses  # nothing recorded as failed
    assert all(row["error"].startswith("not run: lost the Dask scheduler") for row in report.values()
               if row["status"] == "not run")
    manifest = json.loads((out / "onestroke-batch-manifest.json").read_text())
    assert manifest["failed"] == {}
    # the rerun, on a new cluster, makes the rest: the same bytes as an undisturbed run
    cluster, address = _local_cluster()
    try:
        rerun = CliRunner().invoke(main, ["batch", str(folder), "-o", str(out), "--to", "svg,pes",
                                          "--scheduler", address])
    finally:
        cluster.kill()
        cluster.wait()
    assert rerun.exit_code == 0, rerun.output
    assert sorted(row["status"] for row in read_report(out).values()) == \
        sorted("skipped" if s == "ok" else "ok" for s in statuses)
    assert outputs_of(out) == reference


def test_disk_full_on_the_second_of_two_outputs_leaves_neither(tmp_path):
    """A tiny tmpfs per command, sized (from a run on the real disk) to hold the first output
    and one page more, not the second output (the preview, the first stage image)."""
    page = 4096
    commands = {"pes": ["embroider", str(LOOPS), "-o", "{d}/a.pes", "--preview", "{d}/a.png"],
                "gcode": ["laser", str(LOOPS), "-o", "{d}/a.gcode", "--preview", "{d}/a.png"],
                "svg": ["vectorize", str(LOOPS), "-o", "{d}/a.svg", "--debug", "{d}/debug"]}
    mounts, rows, seconds = [], [], {}
    for name, argv in commands.items():
        sized = tmp_path / f"sized-{name}"
        sized.mkdir()
        made = CliRunner().invoke(main, [a.replace("{d}", str(sized)) for a in argv])
        assert made.exit_code == 0, made.output
        first = (sized / f"a.{name}").stat().st_size
        second = sized / ("debug/1-binary.png" if name == "svg" else "a.png")
        assert second.stat().st_size > page  # it cannot fit in the page left
        disk = tmp_path / name
        disk.mkdir()
        mounts.append(tmpfs(disk, f"{(first + page - 1) // page * page + page}"))
        rows.append(([a.replace("{d}", str(disk)) for a in argv], str(disk)))
        seconds[name] = str(disk / second.relative_to(sized))
    for (argv, folder), result, name in zip(rows, run_with_mounts(mounts, rows), commands):
        assert result["code"] == 1, result
        assert result["stderr"].strip() == f"error: cannot write {seconds[name]!r}: the disk is full", result
        assert result["left"] == [], result  # neither output, no temporary file, no debug folder
        assert os.listdir(folder) == []  # the mount point, empty again outside the namespace


def test_a_batch_on_a_disk_that_fills_up_writes_its_report_and_says_why(drawings, tmp_path):
    folder, reference, _ = drawings
    disk = tmp_path / "disk"
    disk.mkdir()
    out = disk / "out"
    argv = ["batch", str(folder), "-o", str(out), "--to", "svg,pes", "--jobs", "1"]
    results = run_with_mounts([tmpfs(disk, "40k")], [
        (argv, str(disk)),
        ("cp -r " + str(out) + " " + str(tmp_path / "first"), None),  # what the full disk held
        (f"mount -o remount,size=1m tmpfs {disk}", None), (argv, str(disk))])
    first, _, _, second = results
    lines = first["stderr"].strip().splitlines()
    assert first["code"] == 1 and len(lines) == 1 and "the disk is full" in lines[0], first
    assert "the batch stopped" in lines[0] and "report: " in lines[0]
    report = read_report(tmp_path / "first")
    made = [name for name, row in report.items() if row["status"] == "ok"]
    assert 1 <= len(made) < 6 and {row["status"] for row in report.values()} == {"ok", "not run"}
    assert all("the disk is full" in row["error"] for row in report.values() if row["status"] == "not run")
    kept = outputs_of(tmp_path / "first")
    assert all(reference[name] == content for name, content in kept.items())
    assert len(kept) == 2 * len(made)  # every drawing made has both its outputs, the others none
    assert not [name for name in first["left"] if name.endswith(".part") or "reserve" in name]
    assert second["code"] == 0, second  # room again: the same command finishes the batch
    assert len([name for name in second["left"] if name.endswith((".svg", ".pes"))]) == 12


def _server(kind: str) -> tuple[socket.socket, int]:
    """A TCP server on a free port: "http" answers HTTP requests, "banner" greets with a line."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen()

    def serve() -> None:
        while True:
            try:
                connection, _ = listener.accept()
            except OSError:
                return
            with connection:
                if kind == "banner":
                    connection.sendall(b"SSH-2.0-OpenSSH_9.2p1\r\n")
                else:
                    connection.recv(4096)
                    connection.sendall(b"HTTP/1.1 200 OK\r\nContent-Length: 0\r\n\r\n")
                time.sleep(0.5)

    threading.Thread(target=serve, daemon=True).start()
    return listener, listener.getsockname()[1]


@pytest.mark.parametrize("kind,message", [
    ("http", "an HTTP server is there (HTTP/1.1 200 OK), not a Dask scheduler"),
    ("banner", "a server there answered 'SSH-2.0-OpenSSH_9.2p1'; not a Dask scheduler"),
    ("nothing", "nothing is listening there (connection refused)")])
def test_a_wrong_scheduler_address_is_named_within_seconds(tmp_path, kind, message):
    if kind == "nothing":
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        port = listener.getsockname()[1]
        listener.close()
    else:
        listener, port = _server(kind)
    started = time.perf_counter()
    result = CliRunner().invoke(main, ["batch", str(LOOPS), "-o", str(tmp_path / "out"), "--scheduler",
                                       f"tcp://127.0.0.1:{port}"])
    seconds = time.perf_counter() - started
    listener.close()
    assert result.exit_code == 1 and message in result.stderr, result.output
    assert result.output.count("\n") == 1 and seconds < 20
    assert not (tmp_path / "out").exists()  # refused before anything started


def test_without_the_dask_extra_nothing_starts(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # what `import distributed` meets without it
    out = tmp_path / "out"
    assert CliRunner().invoke(main, ["batch", str(LOOPS), "-o", str(out), "--to", "svg", "--jobs", "1"]).exit_code == 0
    result = CliRunner().invoke(main, ["batch", str(LOOPS), "-o", str(out), "--to", "svg", "--scheduler",
                                       "tcp://127.0.0.1:8786"])
    assert result.exit_code == 2 and result.output == \
        "error: --scheduler needs the dask extra: pip install 'onestroke[dask]' (on this machine and on every worker)\n"


def test_a_drawing_whose_worker_died_is_not_remembered_as_failed(tmp_path):
    """A worker's death is not the input's fault: the manifest keeps no failure for it, so
    a plain rerun tries it again."""
    from fabrication.batch import find_inputs
    from fabrication.batch.manifest import Manifest
    from fabrication.batch.runner import _store
    from fabrication.batch.work import FileResult

    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "a.png").write_bytes(LOOPS.read_bytes())
    (folder / "b.png").write_bytes(LOOPS.read_bytes())
    out = tmp_path / "out"
    out.mkdir()
    items = find_inputs([folder], out, ("svg",), ("png",))
    manifest = Manifest(out)
    lost = _store(items[0], FileResult(name="a.png", error="its worker process died 2 times", worker_lost=True),
                  {"svg": "k"}, manifest, "k")
    bad = _store(items[1], FileResult(name="b.png", error="not a drawing"), {"svg": "k"}, manifest, "k")
    assert (lost.status, bad.status) == ("failed", "failed")
    assert list(manifest.failed) == ["b.png"]
