#!/usr/bin/env python
"""Cost of the intersection CNN per intersection, with its 8-fold test-time augmentation.

    python -m benchmarks.classifier_speed                 # both parts
    python -m benchmarks.classifier_speed --count 40      # drawings of the "touch" set

Part 1 (in the pipeline): vectorizes the benchmark's "touch" drawings with the CNN and
divides the time of the "classification" stage (crops + 8 copies + one onnxruntime call)
by the number of intersections classified. The session is warmed up once first, as in
a long-running process; the first-call cost is printed separately.
Part 2 (classifier alone): `CnnClassifier.classify` on a rendered drawing with 1, 5, 20
and 50 junctions at once.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np


def pipeline_part(count: int) -> None:
    from benchmarks.sets.drawings import generate_set
    from benchmarks.common.render import render, to_uint8
    from vectorize import VectorizeOptions, vectorize_image

    drawings = generate_set("touch", count)
    seconds, junctions, per_drawing = 0.0, 0, []
    options = VectorizeOptions(classifier="cnn", seed=0)
    first = time.perf_counter()
    vectorize_image(to_uint8(render(drawings[0].drawing)), options)  # warm-up: session, imports
    print(f"first vectorize call (includes onnxruntime session creation): {time.perf_counter() - first:.3f} s")
    for gt in drawings:
        report = vectorize_image(to_uint8(render(gt.drawing)), options).report
        t = report.seconds.get("classification", 0.0)
        if report.intersections:
            seconds += t
            junctions += report.intersections
            per_drawing.append(1000.0 * t / report.intersections)
    print(f"pipeline, touch set: {len(drawings)} drawings, {junctions} intersections classified")
    if junctions:
        print(f"  classification stage: {1000.0 * seconds / junctions:.2f} ms per intersection overall; "
              f"per drawing median {statistics.median(per_drawing):.2f}, max {max(per_drawing):.2f} ms")


def classifier_part() -> None:
    from benchmarks.sets.drawings import generate_set
    from benchmarks.common.render import render
    from vectorize.junctions.cnn_classifier import CnnClassifier
    from vectorize.junctions.intersections import Junction

    gt = generate_set("touch", 1)[0]
    gray = render(gt.drawing).astype(np.float32)
    h, w = gray.shape
    rng = np.random.default_rng(0)
    classifier = CnnClassifier()
    directions = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    for n in (1, 5, 20, 50):
        junctions = [Junction(center=rng.uniform([0, 0], [w, h]), directions=directions, width=gt.width)
                     for _ in range(n)]
        classifier.classify(gray, junctions, gt.width)
        times = []
        for _ in range(5):
            start = time.perf_counter()
            classifier.classify(gray, junctions, gt.width)
            times.append(time.perf_counter() - start)
        best = min(times)
        print(f"classifier alone, {n:2d} junctions x 8 copies ({w}x{h} px, stroke {gt.width:.1f} px): "
              f"{1000.0 * best:.1f} ms per call, {1000.0 * best / n:.2f} ms per intersection")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=40, help="drawings of the touch set (part 1)")
    ap.add_argument("--skip-pipeline", action="store_true")
    args = ap.parse_args()
    if not args.skip_pipeline:
        pipeline_part(args.count)
    classifier_part()
    return 0


if __name__ == "__main__":
    sys.exit(main())
