"""Benchmark: the job-time estimate against the emulator running the job, streamed.

For every job of benchmarks/laser_time.py (straight lines, the dense spiral, vectorized
drawings, the examples) and for dense 4,000-line jobs of 0.1 mm segments, it prints:
- estimate: machines.job_time (planner and serial link modelled; what `onestroke laser`
  and `onestroke stream` print), and which bound it says dominates;
- planner: the estimate's planner-only figure;
- emulator: the machine time of a real character-counting stream (GrblStreamer over a
  pty at 115,200 baud, 2 ms parse per line) into the GRBL emulator (`sim://`'s machine),
  run in a child process like firmware on its own CPU, on the emulator's machine clock
  (`EmulatorStats.job_time`: from the first line sent to the end of the last block or
  the last `ok`, whichever is later); median of --repeat runs;
- diff: estimate / emulator - 1.
The machine clock does not depend on the host's speed or load (machines/emulator_clock.py):
the figures do not change with the load (measured at load averages 12-21), only the wall time does;
a row whose "host timeouts" exceeds 1 had a host stall that may have cost machine time.
`--scale` only sets how fast the emulator paces its replies in wall time.

    python -m benchmarks.laser_estimate_vs_emulator [--scale 2] [--repeat 1] [--only dense] [--count N] [--match TEXT]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.laser_time import PROFILE, jobs
from machines.emulator import EmulatorOptions, GrblEmulator
from machines.gcode_program import program_from_lines
from machines.job_time import estimate_program_time
from machines.ports import open_port
from machines.streamer import GrblStreamer
from benchmarks.stream_bench import make_job


def dense_job(lines: int, step: float, feed: float) -> list[str]:
    """stream_bench's dense single-stroke curve: `lines` G1 moves of `step` mm at `feed` mm/min."""
    return make_job(lines, step, feed).splitlines()


def straight_job(lines: int, step: float, feed: float) -> list[str]:
    """`lines` G1 moves of `step` mm along one straight line: no corners, so the planner
    would run at `feed` and the serial link and the parser set the pace."""
    out = ["G21", "G90", "M4 S600", "G0 X0 Y10", f"F{feed:g}"]
    out += [f"G1X{i * step:.3f}" for i in range(1, lines + 1)]
    return out + ["M5", "G0X0Y0"]


def _serve(conn, scale: float) -> None:
    emulator = GrblEmulator(EmulatorOptions(time_scale=scale, parse_time=PROFILE.parse_time,
                                            baud=PROFILE.baud))
    conn.send(emulator.start_pty())
    conn.recv()  # the host has connected: the job starts with its next line
    emulator.mark_job_start()
    conn.send("marked")
    conn.recv()
    emulator.wait_idle(30.0)
    conn.send(emulator.stats())
    emulator.stop()


def emulated_seconds(lines: list[str], scale: float) -> tuple[float, float, int]:
    """(machine seconds of a character-counting stream, emulator's planner-limited seconds,
    times its clock stopped waiting for the host: 1, at the end, unless the host stalled)."""
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe()
    process = ctx.Process(target=_serve, args=(child, scale), daemon=True)
    process.start()
    device = parent.recv()
    try:
        with GrblStreamer(open_port(device)) as streamer:
            streamer.connect()
            parent.send("connected")
            parent.recv()
            streamer.stream(program_from_lines(lines))
    finally:
        parent.send("stop")
    stats = parent.recv()
    process.join(5)
    return stats.job_time, stats.planner_limited_time, stats.host_timeouts


def row(label: str, lines: list[str], scale: float, repeat: int) -> float:
    job = estimate_program_time(program_from_lines(lines), PROFILE)
    runs = [emulated_seconds(lines, scale) for _ in range(repeat)]
    emulated = statistics.median(r[0] for r in runs)
    diff = job.total_seconds / emulated - 1
    print(f"{label:46s} {len(lines):6d} {job.total_seconds:9.3f} {job.bound:>7s} {job.planner_seconds:9.3f} "
          f"{emulated:9.3f} {diff:+7.2%}  (emulator planner-limited {runs[0][1]:.3f}, host timeouts "
          f"{runs[0][2]})", flush=True)
    return diff


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", type=float, default=2.0, help="emulator time scale")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--only", choices=["all", "jobs", "dense"], default="all")
    parser.add_argument("--count", type=int, default=0, help="only the first N jobs of each kind (0: all)")
    parser.add_argument("--match", default="", help="only jobs whose label contains this text")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"emulator {args.scale:g}x, {PROFILE.baud} baud, parse {PROFILE.parse_time * 1000:g} ms/line, "
          f"RX {PROFILE.rx_buffer} B, {PROFILE.planner_blocks} blocks; load average {load:.1f}")
    print(f"{'job':46s} {'lines':>6s} {'estimate':>9s} {'bound':>7s} {'planner':>9s} {'emulator':>9s} {'diff':>7s}")
    diffs = []
    if args.only in ("all", "jobs"):
        for number, (label, lines) in enumerate(jobs()):
            if args.count and number >= args.count:
                break
            if args.match not in label:
                continue
            diffs.append(row(label, lines, args.scale, args.repeat))
    if args.only in ("all", "dense"):
        print("dense jobs: 4,000 lines; the emulator's time is what a character-counting stream at "
              f"{PROFILE.baud} baud allows")
        dense = ((0.1, 3000), (0.1, 5000), (0.1, 6000), (0.05, 3000), (0.05, 6000))
        for step, feed in dense[:args.count or None]:
            if args.match not in f"dense {step:g} mm segments, F{feed}":
                continue
            diffs.append(row(f"dense {step:g} mm segments, F{feed}", dense_job(4000, step, feed), args.scale,
                             args.repeat))
        for step, feed in ((0.1, 5000), (0.05, 3000))[:args.count or None]:
            label = f"dense {step:g} mm segments on a straight line, F{feed}"
            if args.match in label:
                diffs.append(row(label, straight_job(4000, step, feed), args.scale, args.repeat))
    print(f"largest |diff|: {max(abs(d) for d in diffs):.2%}; finished {time.strftime('%H:%M:%S')}")


if __name__ == "__main__":
    main()
