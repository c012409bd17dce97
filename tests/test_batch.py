"""`onestroke batch`: the same bytes as the single commands, a report, resuming, Dask.

One folder of 20 small drawings (bundled examples and Hershey glyphs at 360 px, an SVG, a
truncated PNG; part of them in a subfolder) is made into SVG, PES and G-code once with two
worker processes; the tests compare that run with `onestroke vectorize/embroider/laser`
file by file, rerun it, and run part of it on a Dask LocalCluster.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from benchmarks.sets.batch_drawings import make_drawing_folder
from fabrication.cli import main

pytestmark = pytest.mark.slow

# Non-default options of each kind, to check they reach the jobs as the single commands'.
BATCH_OPTIONS = ["--size", "60mm", "--style", "triple", "--arcs", "--laser-tolerance", "0.05mm"]
SINGLE_OPTIONS = {"svg": ["vectorize"], "pes": ["embroider", "--size", "60mm", "--style", "triple"],
                  "gcode": ["laser", "--size", "60mm", "--arcs", "--tolerance", "0.05mm"]}
REPORT = "onestroke-batch-report"


def run_cli(*args: str):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def read_report(out: Path) -> dict[str, dict]:
    with open(out / f"{REPORT}.csv", newline="", encoding="utf-8") as handle:
        return {row["input"]: row for row in csv.DictReader(handle)}


def outputs_of(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and not p.name.startswith("onestroke-batch-")}


@pytest.fixture(scope="module")
def first_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("batch")
    drawings = make_drawing_folder(root / "in")
    out = root / "out"
    result = run_cli("batch", root / "in", "-o", out, "--to", "svg,pes,gcode", "--jobs", "2", *BATCH_OPTIONS)
    return root, drawings, out, result


def test_batch_writes_the_single_commands_bytes_and_reports_the_bad_file(first_run, tmp_path):
    root, drawings, out, result = first_run
    assert len(drawings) == 20
    assert result.exit_code == 1, result.output
    report = read_report(out)
    assert len(report) == 20
    failed = {name: row for name, row in report.items() if row["status"] == "failed"}
    assert list(failed) == ["sub/scan-cut-short.png"]
    assert "damaged or truncated" in failed["sub/scan-cut-short.png"]["error"]
    summary = json.loads((out / f"{REPORT}.json").read_text())["summary"]
    assert (summary["ok"], summary["failed"], summary["workers"]) == (19, 1, 2)

    made = outputs_of(out)
    # one file per good input and target, mirroring the input tree; nothing for the bad one
    assert len(made) == 19 * 3
    assert not any(name.startswith("sub/scan-cut-short") for name in made)
    single = tmp_path / "single"
    for drawing in drawings[:-1]:
        relative = drawing.relative_to(root / "in")
        stem = relative.with_suffix("")
        assert report[relative.as_posix()]["outputs"] == "; ".join(f"{stem.as_posix()}.{e}"
                                                                 for e in ("svg", "pes", "gcode"))
        for extension, command in SINGLE_OPTIONS.items():
            target = single / f"{stem}.{extension}"
            target.parent.mkdir(parents=True, exist_ok=True)
            done = run_cli(command[0], drawing, "-o", target, *command[1:])
            assert done.exit_code == 0, done.output
            assert made[f"{stem.as_posix()}.{extension}"] == target.read_bytes(), f"{stem}.{extension} differs"


def test_rerun_skips_everything_quickly_and_keeps_the_failure(first_run):
    root, _, out, _ = first_run
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*.*") if not p.name.startswith("onestroke-batch-")}
    started = time.perf_counter()
    result = run_cli("batch", root / "in", "-o", out, "--to", "svg,pes,gcode", "--jobs", "2", *BATCH_OPTIONS)
    seconds = time.perf_counter() - started
    assert seconds < 2.0
    assert result.exit_code == 1
    assert "19 of 20 drawings are current" in result.output
    report = read_report(out)
    assert sum(row["status"] == "skipped" for row in report.values()) == 19
    assert report["sub/scan-cut-short.png"]["status"] == "failed"
    assert "earlier run" in report["sub/scan-cut-short.png"]["error"]
    assert {p: p.stat().st_mtime_ns for p in before} == before


def test_a_changed_input_or_option_is_made_again(first_run, tmp_path):
    root, drawings, out, _ = first_run
    folder = tmp_path / "in"
    folder.mkdir()
    picked = [d for d in drawings if d.name in ("glyph-HersheySans1-J.png", "glyph-HersheySans1-two.png")]
    for drawing in picked:
        (folder / drawing.name).write_bytes(drawing.read_bytes())
    mine = tmp_path / "out"
    assert run_cli("batch", folder, "-o", mine, "--to", "svg", "--jobs", "1").exit_code == 0
    assert run_cli("batch", folder, "-o", mine, "--to", "svg,gcode", "--jobs", "1").exit_code == 0
    report = read_report(mine)
    assert [row["outputs"] for row in report.values()] == [
        "glyph-HersheySans1-J.svg; glyph-HersheySans1-J.gcode", "glyph-HersheySans1-two.svg; glyph-HersheySans1-two.gcode"]
    assert all(row["status"] == "ok" for row in report.values())
    # a newer input is made again, the other one is not
    newer = folder / "glyph-HersheySans1-J.png"
    os.utime(newer, ns=(time.time_ns() + 10**9,) * 2)
    run_cli("batch", folder, "-o", mine, "--to", "svg,gcode", "--jobs", "1")
    statuses = {name: row["status"] for name, row in read_report(mine).items()}
    assert statuses == {"glyph-HersheySans1-J.png": "ok", "glyph-HersheySans1-two.png": "skipped"}
    # another option: made again, and the same bytes as the first run had with those options
    run_cli("batch", folder, "-o", mine, "--to", "gcode", "--jobs", "1", *BATCH_OPTIONS)
    assert {row["status"] for row in read_report(mine).values()} == {"ok"}
    assert (mine / "glyph-HersheySans1-J.gcode").read_bytes() == (out / "glyph-HersheySans1-J.gcode").read_bytes()


def test_dask_local_cluster_gives_the_same_bytes(first_run, tmp_path):
    from distributed import LocalCluster

    root, drawings, out, _ = first_run
    folder = tmp_path / "in"
    picked = [d for d in drawings if d.name.startswith("glyph-") or d.suffix == ".svg"][:5] + [drawings[-1]]
    for drawing in picked:
        target = folder / drawing.relative_to(root / "in")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(drawing.read_bytes())
    mine = tmp_path / "out"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        result = run_cli("batch", folder, "-o", mine, "--to", "svg,pes,gcode", "--scheduler",
                         cluster.scheduler_address, *BATCH_OPTIONS)
    assert result.exit_code == 1, result.output
    report = read_report(mine)
    assert report["sub/scan-cut-short.png"]["status"] == "failed"
    # the worker read a copy of the bytes; the error names the user's file
    assert "sub/scan-cut-short.png" in report["sub/scan-cut-short.png"]["error"]
    assert json.loads((mine / f"{REPORT}.json").read_text())["summary"]["workers"] == 2
    made = outputs_of(mine)
    assert len(made) == 5 * 3
    reference = outputs_of(out)
    assert all(content == reference[name] for name, content in made.items())


def _child_env() -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                                         os.environ.get("PYTHONPATH", "")])}


def test_a_terminal_gets_a_progress_bar_with_count_rate_and_time_left(first_run, tmp_path):
    import pty

    root, drawings, _, _ = first_run
    folder = tmp_path / "in"
    folder.mkdir()
    for drawing in [d for d in drawings if d.name.startswith("glyph-")][:2]:
        (folder / drawing.name).write_bytes(drawing.read_bytes())
    master, slave = pty.openpty()
    process = subprocess.Popen([sys.executable, "-m", "fabrication.cli", "batch", str(folder), "-o",
                                str(tmp_path / "out"), "--to", "svg", "--jobs", "1"],
                               stdin=slave, stdout=slave, stderr=slave, env=_child_env())
    os.close(slave)
    seen = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        seen += chunk
    os.close(master)
    assert process.wait(timeout=60) == 0
    text = seen.decode("utf-8", "replace")
    assert "drawings" in text and "2/2" in text and "drawings/s" in text and "left" in text
    assert "2 drawings: 2 made, 0 skipped, 0 failed" in text


def _take_ctrl_c() -> None:
    # a suite run as a background job starts children with SIGINT ignored
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_keeps_finished_outputs_and_leaves_no_partial_file(first_run, tmp_path):
    root, _, out, _ = first_run
    mine = tmp_path / "out"
    env = _child_env()
    # its own process group, which Ctrl-C in a terminal signals as a whole (client and workers)
    process = subprocess.Popen([sys.executable, "-m", "fabrication.cli", "batch", str(root / "in"), "-o", str(mine),
                                "--to", "svg", "--jobs", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               env=env, preexec_fn=_take_ctrl_c, start_new_session=True)
    deadline = time.monotonic() + 120
    while not list(mine.rglob("*.svg")) and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    assert b"interrupted" in stderr and b"Traceback" not in stderr
    assert not [p for p in mine.rglob("*") if p.name.endswith(".part")]
    kept = outputs_of(mine)
    assert 1 <= len(kept) < 19, (sorted(kept), stderr)
    reference = outputs_of(out)
    assert all(content == reference[name] for name, content in kept.items())
    statuses = [row["status"] for row in read_report(mine).values()]
    # Ctrl-C between an output's rename and its manifest entry leaves one more file than
    # recorded: the next run makes that one again
    assert statuses.count("ok") in (len(kept), len(kept) - 1) and "not run" in statuses
    # the next run makes only what is missing
    result = run_cli("batch", root / "in", "-o", mine, "--to", "svg", "--jobs", "2")
    report = read_report(mine)
    assert sum(row["status"] == "skipped" for row in report.values()) == statuses.count("ok")
    assert result.exit_code == 1 and len(outputs_of(mine)) == 19
