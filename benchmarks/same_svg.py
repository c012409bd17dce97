#!/usr/bin/env python
"""Do two versions of the vectorizer write the same SVG bytes? (speed work must not change
the output).

    python -m benchmarks.same_svg make /tmp/inputs                 # the inputs, once
    python -m benchmarks.same_svg run /tmp/inputs /work/wt/base-x /tmp/base.json
    python -m benchmarks.same_svg run /tmp/inputs . /tmp/new.json
    python -m benchmarks.same_svg compare /tmp/base.json /tmp/new.json

`make` renders the drawings of every set of `benchmarks/vectorize_bench.py` (seeds 0 and 1,
"kinds" included; --sets/--seeds/--count to take fewer) as the benchmark hands them to the
vectorizer, and saves each as a .npy file (exact bytes, any dtype); the examples/ drawings
are read by path. `run` imports `vectorize` from the given source tree (a git worktree of
the version to check) and writes the SHA-256 of each output's SVG (or the error message):
every drawing single-line, seed-0 drawings also multi-stroke; each examples/ drawing at
several threshold and blur values through one `StageCache` (as the studio does, so the
cached path is checked too), and the same values fresh. The curves (the SVG without its
`data-widths`) and the ink widths are hashed apart, as "KEY" and "KEY widths": versions
before widths existed compare equal on their curves. `compare` lists what differs.

`run --svgs` also keeps every SVG's text (in OUT with `.svgs.json` for `.json`); where both
runs kept them, `compare` says by how much each differing output's numbers differ (the
largest absolute difference of its numbers, in the SVG's units, where both have as many):
for a change whose outputs may differ in rounding only.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import multiprocessing as mp
import re
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.common.checkout import needs_rerun, rerun_on

HERE = Path(__file__).resolve().parents[1]
# The ink widths along a path (vectorize/svg_write.py): hashed apart from the curves, so that
# the curves of versions before and after widths existed compare equal.
WIDTHS = re.compile(r' data-widths="([^"]*)"')
# (threshold, blur) of the examples' runs: Li's threshold and set ones, no blur and blur.
SETTINGS = [(None, 0.0), (0.35, 0.0), (0.5, 0.0), (None, 0.75), (0.4, 0.75), (None, 1.5), (0.45, 2.0)]


def make(folder: Path, sets: list[str], seeds: list[int], count: int | None) -> int:
    import numpy as np

    from benchmarks.common.render import render_truth
    from benchmarks.sets.conditions import condition_image
    from benchmarks.sets.registry import DEFAULT_COUNTS, KINDS_COUNT, build_set

    folder.mkdir(parents=True, exist_ok=True)
    made = 0
    for name in sets:
        for seed in seeds:
            wanted = count or DEFAULT_COUNTS.get(name, KINDS_COUNT)
            for index, gt in enumerate(build_set(name, wanted, seed)):
                gray = render_truth(gt)
                image, _ = condition_image(gt.drawing, gray, gt.meta.get("condition", "clean"),
                                           np.random.default_rng(index))
                np.save(folder / f"{name}-s{seed}-{index:03d}.npy", image)
                made += 1
    print(f"{made} inputs in {folder}")
    return 0


NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _one(task: tuple) -> list[tuple[str, str, str]]:
    """(key, SHA-256 of the SVG or the error, the SVG's text or the error) of each output of
    one drawing."""
    import numpy as np

    from vectorize import VectorizeOptions, vectorize_file, vectorize_image
    from vectorize.svg_write import drawing_to_svg

    key, kind, path, settings = task
    results = []
    try:
        if kind == "npy":
            image = np.load(path)
            for multi in settings:
                drawing = vectorize_image(image, VectorizeOptions(multi=multi, classifier="cnn", seed=0)).drawing
                results.append((f"{key}{' multi' if multi else ''}", drawing_to_svg(drawing)))
        else:
            try:
                from vectorize.refine.edits import Edits
                from vectorize.refine.refine import StageCache
            except ModuleNotFoundError:  # a checkout from before the stage packages
                from vectorize.edits import Edits
                from vectorize.refine import StageCache

            cache = StageCache()  # one per drawing, as the studio keeps
            for threshold, blur in SETTINGS:
                for multi in (False, True):
                    edits = Edits(threshold=threshold, blur=blur, multi=multi)
                    for how, shared in (("cached", cache), ("fresh", None)):
                        drawing = vectorize_file(path, VectorizeOptions(classifier="cnn"), edits=edits,
                                                 cache=shared).drawing
                        results.append((f"{key} t={threshold} b={blur} multi={multi} {how}", drawing_to_svg(drawing)))
    except Exception as exc:  # noqa: BLE001 - a failure is an output to compare too
        return [(key, f"{type(exc).__name__}: {exc}", "")]
    out = []
    for k, svg in results:
        # The curves and the ink widths apart: a change of one shows as that one.
        widths = " ".join(WIDTHS.findall(svg))
        out.append((k, hashlib.sha256(WIDTHS.sub("", svg).encode()).hexdigest(), WIDTHS.sub("", svg)))
        if widths:
            out.append((f"{k} widths", hashlib.sha256(widths.encode()).hexdigest(), widths))
    return out


def _texts_path(out: Path) -> Path:
    return out.with_suffix(".svgs.json")


def run(folder: Path, tree: Path, out: Path, jobs: int, keep_svgs: bool = False) -> int:
    if needs_rerun(tree):  # `vectorize` from that tree, in a child interpreter
        return rerun_on(tree, __file__, ["run", str(folder), str(tree), str(out), "--jobs", str(jobs),
                                         *(["--svgs"] if keep_svgs else [])])
    import vectorize

    source = Path(vectorize.__file__).resolve().parents[1]
    tasks = []
    for path in sorted(folder.glob("*.npy")):
        tasks.append((path.stem, "npy", str(path), (False, True) if "-s0-" in path.stem else (False,)))
    for path in sorted((HERE / "examples").glob("*.png")):
        tasks.append((path.name, "file", str(path), None))
    start = time.perf_counter()
    hashes, texts = {}, {}
    with mp.get_context("fork").Pool(jobs) as pool:
        for outputs in pool.imap_unordered(_one, tasks):
            hashes.update((key, digest) for key, digest, _ in outputs)
            texts.update((key, text) for key, _, text in outputs)
    out.write_text(json.dumps(dict(sorted(hashes.items())), indent=0))
    if keep_svgs:
        _texts_path(out).write_text(json.dumps(dict(sorted(texts.items()))))
    print(f"vectorize from {source}: {len(hashes)} outputs of {len(tasks)} drawings in "
          f"{time.perf_counter() - start:.0f} s -> {out}")
    return 0


def compare(a: Path, b: Path) -> int:
    first, second = json.loads(a.read_text()), json.loads(b.read_text())
    differ = sorted(k for k in first.keys() | second.keys() if first.get(k) != second.get(k))
    errors = sum(1 for k, v in first.items() if len(v) != 64 and not k.endswith(" widths"))
    texts = [json.loads(_texts_path(p).read_text()) if _texts_path(p).exists() else {} for p in (a, b)]
    largest = 0.0
    for key in differ:
        gap = _numbers_apart(texts[0].get(key), texts[1].get(key))
        if gap is not None:
            largest = max(largest, gap)
        print(f"DIFFERS {key}: {first.get(key)} != {second.get(key)}"
              f"{'' if gap is None else f'; numbers apart by up to {gap:.3g}'}")
    curves = [k for k in differ if not k.endswith(" widths")]
    print(f"{len(first)} and {len(second)} hashes; {len(curves)} outputs differ (curves, SVG without "
          f"data-widths), {len(differ) - len(curves)} ink-width profiles differ or are only on one side; "
          f"{errors} are errors in both")
    if differ and all(texts):
        print(f"largest difference of a number between outputs that differ only in their numbers: {largest:.3g}")
    return 1 if differ else 0


def _numbers_apart(first: str | None, second: str | None) -> float | None:
    """The largest absolute difference between the numbers of two texts that differ only in
    their numbers; None otherwise (or where a text was not kept)."""
    if not first or not second or NUMBER.sub("#", first) != NUMBER.sub("#", second):
        return None
    pairs = zip(NUMBER.findall(first), NUMBER.findall(second))
    return max((abs(float(x) - float(y)) for x, y in pairs), default=0.0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    m = sub.add_parser("make")
    m.add_argument("folder", type=Path)
    m.add_argument("--sets", nargs="*", default=None, help="default: every set and kinds")
    m.add_argument("--seeds", nargs="*", type=int, default=[0, 1])
    m.add_argument("--count", type=int, default=None, help="drawings per set (default: the benchmark's)")
    r = sub.add_parser("run")
    r.add_argument("folder", type=Path)
    r.add_argument("tree", type=Path, help="the source tree whose vectorize to run")
    r.add_argument("out", type=Path)
    r.add_argument("--jobs", type=int, default=2)
    r.add_argument("--svgs", action="store_true", help="also keep the SVG texts, for compare to measure differences")
    c = sub.add_parser("compare")
    c.add_argument("a", type=Path)
    c.add_argument("b", type=Path)
    args = ap.parse_args(argv)
    if args.command == "make":
        if args.sets is None:
            from benchmarks.sets.registry import SETS

            args.sets = [*SETS, "kinds"]
        return make(args.folder, args.sets, args.seeds, args.count)
    if args.command == "run":
        return run(args.folder, args.tree, args.out, args.jobs, args.svgs)
    return compare(args.a, args.b)


if __name__ == "__main__":
    sys.exit(main())
