"""Stream a 20,000-line job to the GRBL emulator over a real pty; compare with the planner.

The emulator runs in a child process (like real firmware, it does not share the sender's
interpreter lock) on a pseudo-terminal; the sender opens the pty with pyserial. For each
mode (character counting, send-response) it prints, as medians over --repeat runs: the
run time in machine seconds (the emulator's machine clock, `EmulatorStats.job_time`: the
same whatever the load), the emulator's planner-limited time,
their ratio, RX overflow bytes and whether the emulator's log equals the file.

    python -m benchmarks.stream_bench [--lines 20000] [--scale 4] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py


from machines.emulator import EmulatorOptions, GrblEmulator
from machines.gcode_program import program_from_text
from machines.ports import open_port
from machines.streamer import DRAIN_LINE, GrblStreamer, StreamOptions


def make_job(lines: int, step: float, feed: float) -> str:
    """A dense single-stroke curve of `lines` G1 moves of about `step` mm at `feed` mm/min."""
    out = ["G21", "G90", "M4 S600", "G0 X200 Y200", f"F{feed:g}"]
    x = y = 200.0
    for i in range(lines):
        t = 0.003 * i
        heading = 2.5 * math.sin(t * 1.7) + t
        x += step * math.cos(heading)
        y += step * math.sin(heading)
        out.append(f"G1X{x:.3f}Y{y:.3f}")
    out += ["M5", "G0X0Y0"]
    return "\n".join(out) + "\n"


def _serve(conn, scale: float) -> None:
    emulator = GrblEmulator(EmulatorOptions(time_scale=scale))
    conn.send(emulator.start_pty())
    conn.recv()  # the host has connected: time the job from its next line
    emulator.mark_job_start()
    conn.send("marked")
    conn.recv()  # "stop"
    emulator.wait_idle(10.0)
    stats = emulator.stats()
    conn.send((stats, emulator.executed))
    emulator.stop()


def run_once(text: str, scale: float, send_response: bool) -> dict:
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe()
    process = ctx.Process(target=_serve, args=(child, scale), daemon=True)
    process.start()
    device = parent.recv()
    program = program_from_text(text)
    streamer = GrblStreamer(open_port(device), options=StreamOptions(send_response=send_response))
    try:
        streamer.connect()
        parent.send("connected")
        parent.recv()
        result = streamer.stream(program)
    finally:
        streamer.close()
    parent.send("stop")
    stats, executed = parent.recv()
    process.join(5)
    expected = [line for _, line in program.lines] + [DRAIN_LINE]
    return {"machine_s": stats.job_time, "limited_s": stats.planner_limited_time,
            "ratio": stats.job_time / stats.planner_limited_time, "wall_s": result.elapsed,
            "overflow": stats.rx_overflow_bytes, "max_rx": stats.max_rx_used, "log_ok": executed == expected,
            "lines": len(program)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=20000)
    parser.add_argument("--step", type=float, default=0.25, help="segment length, mm")
    parser.add_argument("--feed", type=float, default=3000.0, help="mm/min")
    parser.add_argument("--scale", type=float, default=4.0, help="emulator time scale")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--modes", default="cc,sr", help="cc (character counting), sr (send-response)")
    args = parser.parse_args()
    text = make_job(args.lines, args.step, args.feed)
    print(f"job: {args.lines} G1 lines of {args.step} mm at F{args.feed:g}; emulator {args.scale:g}x, "
          f"115200 baud, 2 ms parse/line, RX 128 B, 15 blocks; medians of {args.repeat}")
    for mode in args.modes.split(","):
        runs = []
        for _ in range(args.repeat):
            start = time.monotonic()
            runs.append(run_once(text, args.scale, send_response=(mode == "sr")))
            runs[-1]["total_wall"] = time.monotonic() - start
        med = {key: statistics.median(r[key] for r in runs) for key in ("machine_s", "limited_s", "ratio", "wall_s")}
        name = {"cc": "character counting", "sr": "send-response"}[mode]
        print(f"{name:>19}: run {med['machine_s']:.2f} s machine ({med['wall_s']:.2f} s wall), planner-limited "
              f"{med['limited_s']:.2f} s, ratio {med['ratio']:.4f} (runs: "
              + ", ".join(f"{r['ratio']:.4f}" for r in runs)
              + f"); RX overflow {max(r['overflow'] for r in runs)} B, max RX used {max(r['max_rx'] for r in runs)} B,"
              f" log == file in {sum(r['log_ok'] for r in runs)}/{len(runs)} runs")


if __name__ == "__main__":
    main()
