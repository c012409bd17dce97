#!/usr/bin/env python
"""Vectorizer benchmark: one command, one table.

    python -m benchmarks.vectorize_bench                       # all sets, default classifiers
    python -m benchmarks.vectorize_bench --set touch --classifier both --count 30
    python -m benchmarks.vectorize_bench --csv /tmp/bench.csv  # plus one row per drawing
    python -m benchmarks.vectorize_bench --whole-process 5     # time `onestroke vectorize` as a subprocess
    python -m benchmarks.vectorize_bench --ground-truth-as-output   # check the metrics machinery
    python -m benchmarks.vectorize_bench --set plain --condition scan  # scan-like input (benchmarks/sets/conditions.py)

Sets: "plain" (generated, no touches), "touch" (generated, with tangential touches and
near-touches), "hershey" (single-stroke font glyphs), "hershey-retrace" (the glyphs whose
retraced branch cannot be told from the ink, fair-retrace rule), "relief" (Relief
SingleLine glyphs), "triple" (three passes through a point), "handwriting" (jittered
cursive words); "heldout" (not in "all"): glyphs, words and seeds no other set uses, under
scan, JPEG, noise, pen-pressure, broken-line, half-resolution and pencil conditions
(benchmarks/sets/heldout.py); "kinds" (not in "all"): TSP art, brush kana, broad-nib capitals and
phone photos of pen drawings (benchmarks/sets/kinds.py); "cursive" (not in "all"): long cursive words
and short sentences as one line, with overshoot hooks, entry stubs and drifting stem loops
(benchmarks/sets/cursive.py). Classifier "auto" runs the CNN everywhere and the geometric rule on touch
too. See docs/benchmark.md for the columns.

Each drawing is vectorized in a fresh process forked from this one (the vectorizer's
modules and models are loaded here first by a warm-up call, as in a long-running process):
time is the wall time of `vectorize_image` alone; peak memory is that process's peak
resident set size (VmHWM, reset just before the call through /proc/self/clear_refs, so it
covers the call and everything already resident: interpreter, numpy, the model).
"""

from __future__ import annotations

import argparse
import csv
import gc
import multiprocessing as mp
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np

from benchmarks.sets.conditions import CONDITIONS, condition_image
from benchmarks.metrics.tables import PSNR_CAP, print_failures, print_fair_only, print_tables
from benchmarks.metrics.ink import ink_pieces, ink_scores, verdict
from benchmarks.metrics.table1 import ORDER_THRESHOLD, evaluate, order_tolerance
from benchmarks.metrics.route_figures import print_route_figures, route_row
from benchmarks.common.render import render, render_truth, to_uint8
from benchmarks.sets.registry import CURSIVE_COUNT, DEFAULT_COUNTS, HELDOUT_COUNT, KINDS_COUNT, SETS, build_set

ROOT = Path(__file__).resolve().parents[1]

TASKS: list = []  # (set name, GroundTruth), inherited by the forked workers
PLOT_DIR: list = []  # [Path] when --plot is given
CONDITION: list = ["clean"]  # how the rendered page is degraded (benchmarks/sets/conditions.py)


def overlay(gt, output, gray: np.ndarray, path: Path) -> None:
    """The output over the (lightened) input, coloured by drawing order (red -> violet per
    stroke, a black ring at each stroke's start); blue circles: ground-truth crossings; green
    circles: touches; red squares: output intersections."""
    import colorsys

    from PIL import Image, ImageDraw

    from benchmarks.metrics.table1 import drawing_polylines, polyline_intersections

    im = Image.fromarray(to_uint8(0.6 + 0.4 * gray)).convert("RGB")
    draw = ImageDraw.Draw(im)
    for stroke in output.strokes:
        pts = stroke.sample_evenly(2.0)
        n = max(len(pts) - 1, 1)
        for k in range(len(pts) - 1):
            r, g, b = colorsys.hsv_to_rgb(0.8 * k / n, 1.0, 0.85)
            draw.line([tuple(pts[k]), tuple(pts[k + 1])], fill=(int(r * 255), int(g * 255), int(b * 255)), width=2)
        x, y = pts[0]
        draw.ellipse((x - 7, y - 7, x + 7, y + 7), outline=(0, 0, 0), width=2)
    for x, y in gt.intersections:
        draw.ellipse((x - 6, y - 6, x + 6, y + 6), outline=(0, 0, 255), width=2)
    for e in gt.events:
        if e.kind in ("touch", "near-touch"):
            x, y = e.point
            draw.ellipse((x - 10, y - 10, x + 10, y + 10), outline=(0, 170, 0), width=2)
    polys, closed = drawing_polylines(output)
    for x, y in polyline_intersections(polys, closed).crossings:
        draw.rectangle((x - 4, y - 4, x + 4, y + 4), outline=(255, 0, 0), width=2)
    im.save(path)


# -- one drawing, in a child process --------------------------------------------------------

def _peak_rss_mb() -> tuple[float, str]:
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0, "VmHWM"
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, "ru_maxrss"


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _run_one(index: int, classifier: str, oracle: bool, conn) -> None:
    set_name, gt = TASKS[index]
    row = {"set": set_name, "classifier": classifier, "name": gt.name, "kind": gt.kind,
           "width": gt.width, "closed": gt.closed, "gt_intersections": len(gt.intersections),
           "error": ""}
    try:
        gray = render_truth(gt)
        condition = gt.meta.get("condition", CONDITION[0])  # the held-out set brings its own
        row["condition"] = condition
        image, back = condition_image(gt.drawing, gray, condition, np.random.default_rng(index))
        # a photo's shadow is darker than mid-gray: count the pieces of the ink as drawn
        row["one_piece"] = ink_pieces(gray if condition == "photo" else image, gt.width / back) == 1
        if oracle:
            output, seconds, peak, method, report = gt.drawing, 0.0, float("nan"), "none", None
        else:
            from vectorize import VectorizeOptions, vectorize_image

            options = VectorizeOptions(multi=False, classifier=classifier, seed=0)
            gc.collect()
            reset = _reset_peak()
            start = time.perf_counter()
            result = vectorize_image(image, options)
            seconds = time.perf_counter() - start
            peak, method = _peak_rss_mb()
            if not reset:
                method += " (not reset: includes set-up)"
            output, report = result.drawing, result.report
            if back != 1.0:
                from vectorize.drawing import Drawing

                matrix = np.array([[back, 0.0, 0.0], [0.0, back, 0.0]])
                output = Drawing(tuple(s.transformed(matrix) for s in output.strokes),
                                 gt.drawing.width, gt.drawing.height, "px")
        scores = evaluate(gt, output, gray)
        if PLOT_DIR and (not scores.correct or scores.hallucinated):
            overlay(gt, output, gray, PLOT_DIR[0] / f"{set_name}-{classifier}-{gt.name}.png")
        row.update(seconds=seconds, peak_mb=peak, memory_method=method, strokes=scores.stroke_count,
                   ssim=scores.ssim, psnr=scores.psnr, length_ratio=scores.length_ratio,
                   gt_intersections=scores.gt_intersections, out_intersections=scores.out_intersections, matched=scores.matched,
                   order=scores.order, order_correct=scores.correct, **_ink_row(gt, output, scores),
                   **route_row(gt, output, report),
                   warnings=" | ".join(report.warnings) if report is not None else "")
    except BaseException as exc:  # noqa: BLE001 - a failing drawing is a result, not a crash
        row["error"] = f"{type(exc).__name__}: {exc}".replace("\n", " ")[:300]
        row["traceback"] = traceback.format_exc()[-2000:]
    conn.send(row)
    conn.close()


def _ink_row(gt, output, scores) -> dict:
    """Excursion figures and the verdict: the order score's, or for a drawing whose order cannot
    be read from the ink (meta "fair") the fair-retrace rule's (docs/benchmark.md)."""
    ink = ink_scores(gt, output, order_tolerance(gt.width))
    fair = bool(gt.meta.get("fair"))
    correct = verdict(gt, scores, ink)
    return {"excursion": ink.excursion, "excursion_w": ink.excursion_widths, "within": ink.within,
            "headroom": ink.headroom,
            "uncovered": ink.uncovered, "cover_tolerance": order_tolerance(gt.width), "fair": fair,
            "fair_why": gt.meta.get("fair_why", "ambiguous" if fair else ""),
            "out_length": output.length, "min_length": gt.meta.get("min_length", float("nan")),
            "correct": bool(correct)}


def run_tasks(jobs: list[tuple[int, str]], oracle: bool, parallel: int, timeout: float, progress) -> list[dict]:
    """Run (task index, classifier) pairs, each in a fresh forked process."""
    ctx = mp.get_context("fork")
    pending = list(enumerate(jobs))
    running: dict = {}
    rows: list[dict | None] = [None] * len(jobs)
    while pending or running:
        while pending and len(running) < parallel:
            slot, (index, classifier) = pending.pop(0)
            parent, child = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_run_one, args=(index, classifier, oracle, child))
            proc.start()
            child.close()
            running[slot] = (proc, parent, time.monotonic(), index, classifier)
        time.sleep(0.01)
        for slot in list(running):
            proc, parent, started, index, classifier = running[slot]
            row = None
            if parent.poll():
                try:
                    row = parent.recv()
                except EOFError:
                    row = None
            elif proc.is_alive() and time.monotonic() - started < timeout:
                continue
            elif proc.is_alive():
                proc.kill()  # only our own child, by its handle
                row = None
            proc.join()
            if row is None:
                set_name, gt = TASKS[index]
                why = f"timeout after {timeout:.0f} s" if time.monotonic() - started >= timeout else (
                    f"worker died (exit code {proc.exitcode})")
                row = {"set": set_name, "classifier": classifier, "name": gt.name, "kind": gt.kind,
                       "width": gt.width, "closed": gt.closed, "gt_intersections": len(gt.intersections),
                       "error": why}
            rows[slot] = row
            del running[slot]
            progress(row)
    return rows  # type: ignore[return-value]


# -- whole process ----------------------------------------------------------------------------

def whole_process(gts: list, timeout: float, classifier: str) -> None:
    """Time `onestroke vectorize IN.png -o OUT.svg` as a subprocess (interpreter start-up,
    imports, model load, PNG read, SVG write included)."""
    from PIL import Image

    from benchmarks.common.processes import child_cpu_seconds
    from benchmarks.common.user_install import bytecode_note
    from vectorize.svg.svg_read import read_svg

    exe = shutil.which("onestroke")
    base = [exe] if exe else [sys.executable, "-c", "from fabrication.cli import main; main()"]
    extra = [] if classifier in ("auto", "both") else ["--classifier", classifier]
    times, cpus, failed = [], [], 0
    with tempfile.TemporaryDirectory(prefix="onestroke-bench-") as tmp:
        for gt in gts:
            src = Path(tmp) / f"{gt.name}.png"
            out = Path(tmp) / f"{gt.name}.svg"
            Image.fromarray(to_uint8(render_truth(gt))).save(src)
            start, cpu_start = time.perf_counter(), child_cpu_seconds()
            try:
                proc = subprocess.run(base + ["vectorize", str(src), "-o", str(out)] + extra, capture_output=True,
                                      text=True, timeout=timeout)
                code = proc.returncode
                msg = (proc.stdout + proc.stderr).strip().splitlines()[-1:] or [""]
            except subprocess.TimeoutExpired:
                code, msg = "timeout", [""]
            elapsed, cpu = time.perf_counter() - start, child_cpu_seconds() - cpu_start
            strokes = len(read_svg(str(out)).strokes) if out.exists() else "-"
            if code == 0:
                times.append(elapsed)
                cpus.append(cpu)
            else:
                failed += 1
            print(f"  {gt.name:<28} {elapsed:6.2f} s  CPU {cpu:5.2f} s  exit {code}  strokes {strokes}  "
                  f"{msg[0][-90:]}")
    cmd = " ".join(["onestroke vectorize IN.png -o OUT.svg"] + extra)
    print(f"bytecode: {bytecode_note(os.environ)}")
    if times:
        print(f"whole-process `{cmd}`: median {statistics.median(times):.2f} s, max {max(times):.2f} s over "
              f"{len(times)} successful runs; CPU (user+sys) median {statistics.median(cpus):.2f} s; "
              f"{failed} failed")
    else:
        print(f"whole-process `{cmd}`: all {failed} runs failed")


# -- classifier at ground-truth junctions ------------------------------------------------------

def _pass_lengths(stroke, point: np.ndarray, gap: float) -> tuple[float, float]:
    """Arc lengths of the two passes of `stroke` nearest to `point`."""
    s = np.linspace(0.0, stroke.length, max(2, int(stroke.length * 2)))
    d = np.linalg.norm(stroke.points_at_lengths(s) - point, axis=1)
    first = s[np.argmin(d)]
    second = s[np.argmin(np.where(np.abs(s - first) > gap, d, np.inf))]
    return float(first), float(second)


def junction_check(classifiers: list[str]) -> None:
    """Each classifier on crops centred at the ground-truth crossings, touches and
    near-touches of the generated sets, with branch directions measured on the ground truth
    3 widths out: how well it does when the pipeline's junction is exactly right."""
    from vectorize.junctions.classifiers import make_classifier
    from vectorize.junctions.intersections import Junction

    labels = {}
    for name, gt in TASKS:
        if name == "hershey":
            continue
        gray = render(gt.drawing).astype(np.float32)
        junctions, kinds = [], []
        for e in gt.events:
            if e.kind not in ("crossing", "touch", "near-touch"):
                continue
            s1, s2 = _pass_lengths(gt.stroke, e.point, 6 * gt.width)
            out = 3 * gt.width
            ends = gt.stroke.points_at_lengths(np.array([s1 - out, s1 + out, s2 - out, s2 + out]))
            dirs = ends - e.point
            dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
            junctions.append(Junction(center=np.asarray(e.point, dtype=float), directions=dirs, width=gt.width))
            kinds.append(e.kind if e.kind != "crossing" else ("crossing <20 deg" if e.angle < 20 else
                                                                "crossing >=20 deg"))
        for c in classifiers:
            verdicts = make_classifier(c).classify(gray, junctions, gt.width)
            for kind, v in zip(kinds, verdicts):
                ok = v.is_crossing == kind.startswith("crossing")
                labels.setdefault((c, kind), []).append(ok)
    print("classifier verdicts at ground-truth junctions (crop centred on the true point, branch "
          "directions 3 widths out on the true curve):")
    for (c, kind), oks in sorted(labels.items()):
        print(f"  {c:<10} {kind:<18} {sum(oks):>4}/{len(oks):<4} correct  {100.0 * sum(oks) / len(oks):5.1f} %")


# -- main -------------------------------------------------------------------------------------

def _load() -> str:
    try:
        return " ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:
        return "?"


def _git_commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip()
    except Exception:  # noqa: BLE001
        return "?"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1], formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--set", default="all", choices=[*SETS, "heldout", "kinds", "cursive", "all"],
                    help="all: every set but heldout and kinds (the drawings and conditions no set tunes on) and "
                         "cursive (long lines)")
    ap.add_argument("--classifier", default="auto", choices=["auto", "cnn", "geometric", "both"],
                    help="auto: cnn on plain/hershey, both on touch")
    ap.add_argument("--count", type=int, default=None, help="drawings per set (default: plain 42, touch 40, "
                                                            "hershey 40)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--name", action="append", default=None, metavar="TEXT",
                    help="only the drawings whose name contains TEXT (repeatable; the set is built as usual first)")
    ap.add_argument("--condition", default="clean", choices=CONDITIONS,
                    help="degrade each rendered page like a real input (see benchmarks/sets/conditions.py)")
    ap.add_argument("--scale", type=float, default=1.0,
                    help="draw every drawing this many times larger on a canvas as much larger (e.g. 3.5: "
                         "3500 px pages; the vectorizer's max_size still applies)")
    ap.add_argument("--jobs", type=int, default=1, help="drawings in parallel (timing is cleanest with 1)")
    ap.add_argument("--csv", type=Path, default=None, help="write one row per drawing here")
    ap.add_argument("--plot", type=Path, default=None, metavar="DIR",
                    help="write an overlay PNG of every drawing that is not one stroke in the correct order "
                         "or reports a crossing the ground truth does not have")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per drawing before it counts as failed")
    ap.add_argument("--whole-process", type=int, nargs="?", const=5, default=None, metavar="N",
                    help="instead: time `onestroke vectorize` as a subprocess on N drawings (default 5)")
    ap.add_argument("--junction-check", action="store_true",
                    help="instead: the classifiers on crops at the ground-truth crossings and touches")
    ap.add_argument("--ground-truth-as-output", action="store_true",
                    help="score the ground truth against itself (checks the machinery; no vectorizer)")
    args = ap.parse_args(argv)

    t_start = time.perf_counter()
    CONDITION[0] = args.condition
    if args.plot:
        args.plot.mkdir(parents=True, exist_ok=True)
        PLOT_DIR.append(args.plot)
    sets = list(SETS) if args.set == "all" else [args.set]
    for name in sets:
        count = args.count if args.count is not None else DEFAULT_COUNTS.get(
            name, {"kinds": KINDS_COUNT, "cursive": CURSIVE_COUNT}.get(name, HELDOUT_COUNT))
        gts = build_set(name, count, args.seed)
        if args.name:
            gts = [gt for gt in gts if any(text in gt.name for text in args.name)]
        if args.scale != 1.0:
            from benchmarks.sets.kinds import scaled

            gts = [scaled(gt, args.scale) for gt in gts]
        TASKS.extend((name, gt) for gt in gts)
    t_gen = time.perf_counter() - t_start

    print(f"onestroke vectorizer benchmark  {time.strftime('%Y-%m-%d %H:%M:%S %Z')}  commit {_git_commit()}  "
          f"python {platform.python_version()}  {os.cpu_count()} CPUs")
    print(f"sets {', '.join(sets)}; condition {args.condition}; seed {args.seed}; {len(TASKS)} drawings made in {t_gen:.1f} s; "
          f"load average {_load()} (timings are inflated when it exceeds the {os.cpu_count()} CPUs)")

    if args.whole_process is not None:
        picks = [gt for _, gt in TASKS[:: max(1, len(TASKS) // args.whole_process)]][: args.whole_process]
        whole_process(picks, args.timeout, args.classifier)
        return 0

    if args.junction_check:
        junction_check(["cnn", "geometric"] if args.classifier in ("auto", "both") else [args.classifier])
        return 0

    jobs: list[tuple[int, str]] = []
    for index, (name, _gt) in enumerate(TASKS):
        if args.classifier == "auto":
            classifiers = ["cnn", "geometric"] if name == "touch" else ["cnn"]
        elif args.classifier == "both":
            classifiers = ["cnn", "geometric"]
        else:
            classifiers = [args.classifier]
        jobs.extend((index, c) for c in classifiers)
    jobs.sort(key=lambda j: (j[1] != "cnn", j[0]))

    if args.ground_truth_as_output:
        print("ground truth scored as the output: every score must be perfect")
    else:
        # warm-up: load the vectorizer and its models once, like a long-running process
        from vectorize import VectorizeOptions, vectorize_image

        for classifier in sorted({c for _, c in jobs}):
            start = time.perf_counter()
            try:
                vectorize_image(to_uint8(render_truth(TASKS[0][1])), VectorizeOptions(classifier=classifier))
                print(f"warm-up ({classifier}): {time.perf_counter() - start:.2f} s")
            except Exception as exc:  # noqa: BLE001
                print(f"warm-up ({classifier}) failed: {type(exc).__name__}: {exc}")
        print("time = wall time of vectorize_image per drawing, each in a fresh forked process; "
              "peak MB = that process's peak RSS during the call (VmHWM reset before it; includes "
              "interpreter, libraries and model)")
    print(f"correct = one stroke and order score >= {ORDER_THRESHOLD}; intersections matched within 5 px, "
          f"pooled over the set; PSNR capped at {PSNR_CAP:.0f} dB")
    print()

    done = [0]

    def progress(row):
        done[0] += 1
        status = row["error"] or (f"strokes {row['strokes']} order {row['order']:.3f} "
                                  f"{row['seconds']:.2f} s")
        print(f"[{done[0]:>3}/{len(jobs)}] {row['set']:<7} {row['classifier']:<9} {row['name']:<34} {status}",
              file=sys.stderr, flush=True)

    rows = run_tasks(jobs, args.ground_truth_as_output, max(1, args.jobs), args.timeout, progress)
    print_tables(rows)
    print_failures(rows)
    print_fair_only(rows)
    print_route_figures(rows)
    errors = [r for r in rows if r.get("error")]
    if errors:
        print()
        print(f"{len(errors)} drawings failed; first errors:")
        for r in errors[:5]:
            print(f"  {r['set']}/{r['classifier']}/{r['name']}: {r['error']}")
    if args.csv:
        keys = ["set", "classifier", "name", "kind", "width", "closed", "strokes", "order", "correct", "ssim",
                "psnr", "length_ratio", "gt_intersections", "out_intersections", "matched", "seconds",
                "peak_mb", "condition", "order_correct", "fair", "fair_why", "one_piece", "excursion", "excursion_w",
                "within", "headroom", "uncovered",
                "cover_tolerance", "out_length", "min_length", "odd_nodes_gt", "odd_nodes", "route_min",
                "route_ratio", "drawn_ratio", "error", "warnings"]
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
            writer.writeheader()
            writer.writerows(rows)
        print(f"per-drawing rows: {args.csv}")
    print(f"\ntotal benchmark time {time.perf_counter() - t_start:.0f} s; load average now {_load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
