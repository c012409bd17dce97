"""The fault cases of issue 28 (items 6-9), run for real, one line of outcome each.

    python -m benchmarks.fault_cases [--src TREE] [--only 6,7] [--markdown]

Every case runs whole `onestroke` commands in child processes (`python -m fabrication.cli`,
with TREE first on PYTHONPATH, so a checkout of another commit can be measured with the
same script: `git archive COMMIT | tar -x -C /tmp/before`). Full disks and read-only
folders are real: a tiny tmpfs or a read-only tmpfs mounted in a private mount namespace
(`unshare -Urm`, which needs no root), and a folder made immutable with `chattr +i` (root
only: root ignores permission bits, not the immutable flag). Workers, batch parents and
Dask schedulers are killed with real signals. Prints what each case gave: exit code,
message, files left, processes left.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import os
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.common.processes import alive, children, cpu_ticks, rss_mb, workers_of

ROOT = Path(__file__).resolve().parents[1]


class Cli:
    """Runs `onestroke` commands of the source tree `src` in child processes."""

    def __init__(self, src: Path, work: Path) -> None:
        self.src, self.work = src, work
        self.env = {**os.environ, "PYTHONPATH": str(src), "PYTHONDONTWRITEBYTECODE": "1"}
        self.env.pop("FORCE_COLOR", None)

    def argv(self, *args) -> list[str]:
        return [sys.executable, "-m", "fabrication.cli", *map(str, args)]

    def run(self, *args, mounts: tuple[str, ...] = (), listing: Path | None = None, timeout: float = 300,
            prelude: str = "") -> tuple[int, str, str, float]:
        """(exit code, stdout, stderr, seconds). mounts: shell commands run first in a private
        mount namespace; listing: a folder whose files are listed (inside the namespace)
        into LISTING.txt beside the work folder. prelude: python run before the CLI."""
        command = self.argv(*args)
        if prelude:
            command = [sys.executable, "-c", prelude + "\nfrom fabrication.cli import main\nmain()", *map(str, args)]
        if mounts:
            script = " && ".join(mounts) + " && { " + shlex.join(command) + "; rc=$?; "
            if listing is not None:
                script += f"(cd {shlex.quote(str(listing))} && find . -type f | sort) > {self.work}/listing.txt; "
            script += "exit $rc; }"
            command = ["unshare", "-Urm", "sh", "-c", script]
        started = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=self.env, timeout=timeout,
                              cwd=self.work)
        return done.returncode, done.stdout, done.stderr, time.perf_counter() - started

    def popen(self, *args, **kwargs) -> subprocess.Popen:
        """A command in the background, its output in files (not pipes: a worker left behind
        would hold a pipe open for good); `finish(process)` waits and gives its stderr."""
        handles = [open(self.work / f"{name}.txt", "w+") for name in ("stdout", "stderr")]
        process = subprocess.Popen(self.argv(*args), stdout=handles[0], stderr=handles[1], text=True,
                                   env=self.env, cwd=self.work, **kwargs)
        process.handles = handles
        return process

    @staticmethod
    def finish(process: subprocess.Popen, timeout: float = 600) -> str:
        """Wait for `process` (killed after `timeout` s) and return its stderr."""
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
        err = process.handles[1]
        err.seek(0)
        text = err.read()
        for handle in process.handles:
            handle.close()
        return text

    def listing(self) -> list[str]:
        path = self.work / "listing.txt"
        return path.read_text().split() if path.exists() else []


def first_error(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("error") or "Traceback" in line or "Error" in line]
    text = (errors or lines or ["(nothing)"])[0]
    extra = f" [+{len(lines) - 1} more lines]" if len(lines) > 1 else ""
    return (text[:150] + ("..." if len(text) > 150 else "")) + extra


def wait_for(condition, timeout: float, step: float = 0.05) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(step)
    return False


def report_rows(out: Path) -> dict[str, dict]:
    path = out / "onestroke-batch-report.csv"
    if not path.exists():
        return {}
    with open(path, newline="", encoding="utf-8") as handle:
        return {row["input"]: row for row in csv.DictReader(handle)}


def statuses(rows: dict[str, dict]) -> str:
    counts: dict[str, int] = {}
    for row in rows.values():
        counts[row["status"]] = counts.get(row["status"], 0) + 1
    return ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) or "no report"


def made_files(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and not p.name.startswith(("onestroke-batch-", "."))}


# -- the cases -------------------------------------------------------------------------------

def item6(cli: Cli, work: Path) -> Iterator[tuple[str, str]]:
    png = work / "in" / "loops.png"
    ro, imm = work / "ro", work / "imm"
    ro.mkdir()
    imm.mkdir()
    ro_mount = (f"mount -t tmpfs -o ro,size=1m tmpfs {ro}",)

    def code(label, *args, mounts=()) -> tuple[str, str]:
        rc, _, err, _ = cli.run(*args, mounts=mounts)
        return label, f"exit {rc}: {first_error(err)}"

    yield code("vectorize -o RO/a.svg (read-only mount)", "vectorize", png, "-o", ro / "a.svg", mounts=ro_mount)
    yield code("batch -o RO/newdir (read-only mount)", "batch", png, "-o", ro / "newdir", mounts=ro_mount)
    immutable = os.geteuid() == 0 and subprocess.run(["chattr", "+i", str(imm)]).returncode == 0
    if immutable:
        try:
            yield code("vectorize -o IMM/a.svg (chattr +i folder)", "vectorize", png, "-o", imm / "a.svg")
            yield code("batch -o IMM/newdir (chattr +i folder)", "batch", png, "-o", imm / "newdir")
            yield code("embroider --preview IMM/p.png (chattr +i)", "embroider", png, "-o", work / "x.pes",
                 "--preview", imm / "p.png")
        finally:
            subprocess.run(["chattr", "-i", str(imm)])
    yield code("vectorize -o /proc/a.svg", "vectorize", png, "-o", "/proc/a.svg")
    yield code("vectorize -o /proc/self/a.svg", "vectorize", png, "-o", "/proc/self/a.svg")
    yield code("vectorize -o missing/a.svg", "vectorize", png, "-o", work / "missing" / "a.svg")
    yield code("vectorize on a full disk", "vectorize", png, "-o", ro / "a.svg",
         mounts=(f"mount -t tmpfs -o size=4k tmpfs {ro}", f"dd if=/dev/zero of={ro}/fill bs=4k count=1 2>/dev/null"))
    # the emulator with a log it can never write: refused at once, or only when stopped?
    process = cli.popen("emulator", "--log", "/proc/x.log")
    started = time.perf_counter()
    try:
        process.wait(timeout=8)
        outcome = f"exit {process.returncode} after {time.perf_counter() - started:.1f} s: " \
                  f"{first_error(cli.finish(process))}"
    except subprocess.TimeoutExpired:
        process.send_signal(signal.SIGINT)
        err = cli.finish(process, timeout=30)
        outcome = f"still running after 8 s; at Ctrl-C exit {process.returncode}: {first_error(err)}"
    yield ("emulator --log /proc/x.log", outcome)


def item7(cli: Cli, work: Path) -> Iterator[tuple[str, str]]:
    png = work / "in" / "loops.png"
    disk = work / "disk"
    disk.mkdir()

    def second_does_not_fit(first: str, *args, label: str) -> tuple[str, str]:
        """Run once on the real disk to size a tmpfs that holds the first output and one page
        more, then again on that tmpfs: the second output meets a full disk."""
        sized = work / "sized"
        shutil.rmtree(sized, ignore_errors=True)
        sized.mkdir()
        cli.run(*[str(a).replace(str(disk), str(sized)) for a in args])
        size = ((sized / first).stat().st_size + 4095) // 4096 * 4096 + 4096
        rc, _, err, _ = cli.run(*args, mounts=(f"mount -t tmpfs -o size={size} tmpfs {disk}",), listing=disk)
        return label, f"exit {rc}: {first_error(err)}; left: {', '.join(cli.listing()) or 'nothing'}"

    yield second_does_not_fit("a.pes", "embroider", png, "-o", disk / "a.pes", "--preview", disk / "a.png",
                              label="embroider --preview, disk full at the preview")
    yield second_does_not_fit("a.gcode", "laser", png, "-o", disk / "a.gcode", "--preview", disk / "a.png",
                              label="laser --preview, disk full at the preview")
    yield second_does_not_fit("a.svg", "vectorize", png, "-o", disk / "a.svg", "--debug", disk / "debug",
                              label="vectorize --debug, disk full at the stage images")
    batch_in = work / "in-batch"
    rc, out, err, _ = cli.run("batch", batch_in, "-o", disk / "out", "--to", "svg,pes,gcode", "--jobs", "1",
                              mounts=(f"mount -t tmpfs -o size=64k tmpfs {disk}",), listing=disk)
    left = cli.listing()
    report = [n for n in left if "report" in n]
    yield ("batch on a disk that fills up", f"exit {rc}: {first_error(err)}; {len(left)} files left, "
                 f"report {'written' if report else 'missing'}, manifest "
                 f"{'written' if any('manifest' in n for n in left) else 'missing'}")


def _batch_folder(work: Path, name: str, count: int) -> Path:
    folder = work / name
    shutil.copytree(work / "in-batch", folder)
    for path in sorted(folder.rglob("*.png"))[count:]:
        path.unlink()
    return folder


def item8(cli: Cli, work: Path) -> Iterator[tuple[str, str]]:
    # a worker killed (as the OOM killer would) while it works on a drawing
    folder = _batch_folder(work, "in-kill", 6)
    out = work / "out-kill"
    process = cli.popen("batch", folder, "-o", out, "--to", "svg,pes", "--jobs", "2")
    killed = None
    if wait_for(lambda: len(list(out.rglob("*.svg"))) >= 1 or process.poll() is not None, 300):
        workers = workers_of(process.pid)
        ticks = {w: cpu_ticks(w) for w in workers}
        time.sleep(0.2)
        busy = [w for w in workers if cpu_ticks(w) > ticks[w]] or workers
        if busy and process.poll() is None:
            killed = busy[0]
            os.kill(killed, signal.SIGKILL)
    err = cli.finish(process)
    rows_first = report_rows(out)
    retried = sum("retried" in (r.get("warnings") or "") or "again" in (r.get("warnings") or "")
                  for r in rows_first.values())
    rc2, out2, _, _ = cli.run("batch", folder, "-o", out, "--to", "svg,pes", "--jobs", "2")
    yield ("a worker killed mid-batch (6 drawings, 2 workers)",
                 f"{'killed a busy worker' if killed else 'no worker to kill'}; exit {process.returncode}: "
                 f"{statuses(rows_first)}; rows noting a retry: {retried}; errors: "
                 f"{first_error(err) if process.returncode else '-'}")
    yield ("  ... then a plain rerun", f"exit {rc2}: {statuses(report_rows(out))}; {out2.strip()[:120]}")

    # the batch parent signalled: are its workers left behind?
    for name, signum in (("SIGTERM", signal.SIGTERM), ("SIGHUP", signal.SIGHUP), ("SIGKILL", signal.SIGKILL)):
        folder = _batch_folder(work, f"in-{name}", 6)
        out = work / f"out-{name}"
        process = cli.popen("batch", folder, "-o", out, "--to", "svg", "--jobs", "2", start_new_session=True)
        wait_for(lambda: len(workers_of(process.pid)) >= 2 and len(list(out.rglob("*.svg"))) >= 1
                 or process.poll() is not None, 300)
        workers = workers_of(process.pid)
        tracker = [c for c in children(process.pid) if c not in workers]
        process.send_signal(signum)
        cli.finish(process, timeout=30)
        time.sleep(5)
        left = [p for p in workers + tracker if alive(p)]
        rss = rss_mb(left)
        yield (f"batch parent sent {name} (2 workers)",
                     f"exit {process.returncode}; after 5 s {len(left)} of {len(workers + tracker)} child "
                     f"processes left ({rss:.0f} MB); report: {statuses(report_rows(out))}")
        for pid in left:  # the orphans this script made, by pid
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)

    # a resumed run: do skipped rows keep the figures of the run that made them?
    folder = _batch_folder(work, "in-resume", 2)
    out = work / "out-resume"
    cli.run("batch", folder, "-o", out, "--to", "svg,pes", "--jobs", "1")
    first = report_rows(out)
    cli.run("batch", folder, "-o", out, "--to", "svg,pes", "--jobs", "1")
    second = report_rows(out)
    row = next(iter(second.values()))
    fields = ("strokes", "stitches", "sew_seconds", "seconds")
    yield ("resumed run: a skipped row's figures",
                 f"status {row['status']}: " + ", ".join(f"{f}={row[f] or '(empty)'}" for f in fields)
                 + f"; first run had " + ", ".join(f"{f}={next(iter(first.values()))[f]}" for f in fields))


def _cluster(cli: Cli) -> tuple[subprocess.Popen, str]:
    """A LocalCluster (scheduler and one worker thread) in its own process; its address."""
    code = ("import logging, time\nlogging.disable(logging.CRITICAL)\nfrom distributed import LocalCluster\n"
            "c = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol='tcp://', "
            "dashboard_address=None)\nprint(c.scheduler_address, flush=True)\ntime.sleep(3600)\n")
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               text=True, env=cli.env)
    return process, process.stdout.readline().strip()


def _listen(kind: str) -> tuple[socket.socket, threading.Thread, int]:
    """A TCP server on a free port: "http" (a real http.server), "banner" (writes a line at once)."""
    if kind == "http":
        from http.server import HTTPServer, SimpleHTTPRequestHandler

        class Quiet(SimpleHTTPRequestHandler):
            def log_message(self, *args) -> None:
                pass

        server = HTTPServer(("127.0.0.1", 0), Quiet)
        thread = threading.Thread(target=server.serve_forever, daemon=True)
        thread.start()
        return server, thread, server.server_address[1]
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen()

    def serve():
        while True:
            try:
                conn, _ = listener.accept()
            except OSError:
                return
            conn.sendall(b"SSH-2.0-OpenSSH_9.2p1 Debian-2\r\n")
            threading.Timer(30, conn.close).start()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    return listener, thread, listener.getsockname()[1]


def item9(cli: Cli, work: Path) -> Iterator[tuple[str, str]]:
    folder = _batch_folder(work, "in-dask", 6)
    out = work / "out-dask"
    cluster, address = _cluster(cli)
    process = cli.popen("batch", folder, "-o", out, "--to", "svg,pes", "--scheduler", address)
    wait_for(lambda: len(list(out.rglob("*.svg"))) >= 1 or process.poll() is not None, 300)
    cluster.kill()
    cluster.wait()
    err = cli.finish(process, timeout=120)
    code = process.returncode if process.returncode != -signal.SIGKILL else "hung (killed after 120 s)"
    rows_first = report_rows(out)
    multiline = sum("\n" in (r.get("error") or "") for r in rows_first.values())
    traceback = "Traceback" in err or "ClosedClientError" in err
    kept = made_files(out)
    yield ("scheduler killed mid-run (6 drawings)",
                 f"exit {code}: {first_error(err)}; report {statuses(rows_first)}; multi-line errors "
                 f"{multiline}; traceback/ClosedClientError text {'yes' if traceback else 'no'}")
    cluster, address = _cluster(cli)
    try:
        rc, stdout, err, _ = cli.run("batch", folder, "-o", out, "--to", "svg,pes", "--scheduler", address,
                                     timeout=300)
    finally:
        cluster.kill()
        cluster.wait()
    reference = work / "out-dask-reference"
    cli.run("batch", folder, "-o", reference, "--to", "svg,pes", "--jobs", "1")
    same = made_files(out) == made_files(reference)
    yield ("  ... rerun on a new LocalCluster",
                 f"exit {rc}: {statuses(report_rows(out))}; outputs identical to a local run: {same}"
                 f" ({len(kept)} kept from the first run); {first_error(err) if rc else stdout.strip()[:90]}")

    png = work / "in" / "loops.png"
    for kind in ("http", "banner"):
        server, _, port = _listen(kind)
        try:
            rc, _, err, seconds = cli.run("batch", png, "-o", work / f"out-{kind}", "--scheduler",
                                          f"tcp://127.0.0.1:{port}", timeout=90)
            yield (f"--scheduler at {'an HTTP server' if kind == 'http' else 'a server sending a banner'}",
                         f"exit {rc} after {seconds:.1f} s: {first_error(err)}")
        except subprocess.TimeoutExpired:
            yield (f"--scheduler at {'an HTTP server' if kind == 'http' else 'a server sending a banner'}",
                         "still running after 90 s (killed)")
        finally:
            if kind == "http":
                server.shutdown()
            server.server_close() if kind == "http" else server.close()
    free = socket.socket()
    free.bind(("127.0.0.1", 0))
    port = free.getsockname()[1]
    free.close()
    rc, _, err, seconds = cli.run("batch", png, "-o", work / "out-free", "--scheduler", f"tcp://127.0.0.1:{port}",
                                  timeout=90)
    yield ("--scheduler where nothing listens", f"exit {rc} after {seconds:.1f} s: {first_error(err)}")
    # without the dask extra (distributed not importable): what is printed first?
    (work / "out-nodask").mkdir()
    cli.run("batch", png, "-o", work / "out-nodask", "--to", "svg", "--jobs", "1")
    rc, stdout, err, _ = cli.run("batch", png, "-o", work / "out-nodask", "--to", "svg", "--scheduler",
                                 "tcp://127.0.0.1:1", prelude="import sys\nsys.modules['distributed'] = None")
    yield ("--scheduler without the dask extra",
                 f"exit {rc}: stderr {' | '.join(err.strip().splitlines())[:160]!r}; stdout {stdout.strip()[:60]!r}")


def prepare(work: Path) -> None:
    from benchmarks.sets.batch_drawings import make_drawing_folder

    (work / "in").mkdir(parents=True)
    shutil.copy(ROOT / "examples" / "loops.png", work / "in" / "loops.png")
    (work / "in" / "job.gcode").write_text("G21\nG90\nM4 S0\nG0 X5 Y5\nG1 X30 Y5 S600 F1500\nM5\n")
    make_drawing_folder(work / "in-batch", corrupt=False, count=8)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", type=Path, default=ROOT, help="source tree to run (default: this one)")
    parser.add_argument("--only", default="6,7,8,9", help="items to run, e.g. 8,9")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = parser.parse_args()
    items = {"6": item6, "7": item7, "8": item8, "9": item9}
    with tempfile.TemporaryDirectory(prefix="fault-cases-") as folder:
        work = Path(folder)
        prepare(work)
        cli = Cli(args.src.resolve(), work)
        print(f"source: {cli.src}; load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
        for number in args.only.split(","):
            started = time.perf_counter()
            for label, outcome in items[number.strip()](cli, work):
                if args.markdown:
                    print(f"| {number} | {label} | {outcome.replace('|', '/')} |", flush=True)
                else:
                    print(f"{number}  {label:52s} {outcome}", flush=True)
            print(f"   (item {number}: {time.perf_counter() - started:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
