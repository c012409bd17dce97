#!/usr/bin/env python
"""How long route inspection's matching takes on large graphs, alone and within a whole run.

    python -m benchmarks.route_matching_speed                 # 100 odd nodes, and the longest cursive lines
    python -m benchmarks.route_matching_speed --odd 60 100 140 --repeat 5

1. Branch graphs like a long written line (`word_graph`: a wandering spine, stems and stubs
   off it, a few loops), built until they have the asked number of odd nodes: CPU seconds of
   `match_odd` (blossom on the pruned problem), of networkx's blossom on every pair (what it
   would cost without pruning), and of the whole `plan_routes` (shortest paths, costs,
   matching, walk). Medians over --repeat graphs.
2. The longest lines of the `cursive` set and two longer ones, vectorized: the odd nodes
   matched, the matching's CPU seconds and the whole `vectorize_image` call's.

CPU time (`time.process_time`), so the figures hold on a shared machine; the load is printed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np

from vectorize.axis.graph import Branch, MedialGraph


LONG_LINES = ("the kitten and the little duck hated the tall candle",
              "little kettle tilted at the tent and the little duck")


def word_graph(rng: np.random.Generator, spine: int) -> MedialGraph:
    """A branch graph like a long written line: a wandering spine of `spine` nodes, a stem,
    descender or stub off most of them (two odd nodes each), a loop for every 8 spine nodes
    (two spine nodes joined again). Branches are bent polylines, px."""
    graph = MedialGraph()
    position = np.array([0.0, 0.0])
    nodes = []
    for _ in range(spine):
        position = position + [rng.uniform(15, 60), rng.normal(0, 15)]
        nodes.append(graph.add_node(position.copy(), 2.0))

    def join(a: int, b: int) -> None:
        pa, pb = graph.positions[a], graph.positions[b]
        points = np.array([pa, (pa + pb) / 2 + rng.normal(0, 4, 2), pb])
        graph.add_branch(Branch(a, b, points, np.full(3, 2.0), np.ones(2)))

    for a, b in zip(nodes[:-1], nodes[1:]):
        join(a, b)
    for n in nodes[1:-1]:
        if rng.random() < 0.7:
            join(n, graph.add_node(graph.positions[n] + rng.normal(0, 1, 2) * [10, 50], 2.0))
    for _ in range(spine // 8):
        a, b = sorted(rng.choice(len(nodes), 2, replace=False))
        if b - a >= 2:
            join(nodes[a], nodes[b])
    return graph


def odd_count(graph: MedialGraph) -> int:
    return sum(1 for n in graph.incident if graph.degree(n) % 2)


class _Timed:
    """Wraps `route_inspection.match_odd`, keeping (odd nodes, CPU s) per call."""

    def __init__(self) -> None:
        import vectorize.route.route_inspection as ri

        self.module, self.inner, self.calls = ri, ri.match_odd, []
        ri.match_odd = self

    def __call__(self, cost, end_cost):
        start = time.process_time()
        result = self.inner(cost, end_cost)
        self.calls.append((len(cost), time.process_time() - start))
        return result

    def close(self) -> None:
        self.module.match_odd = self.inner


def synthetic(odd_targets: list[int], repeat: int) -> None:
    from scipy.sparse.csgraph import dijkstra

    from vectorize.route.route_inspection import plan_routes
    from vectorize.route.route_matching import SCALE, _blossom

    print("1. word-like branch graphs (CPU s, medians):")
    print(f"   {'odd nodes':>9s} {'graphs':>6s} {'match_odd':>9s} {'blossom, all pairs':>18s} {'plan_routes':>11s}")
    rng = np.random.default_rng(0)
    for target in odd_targets:
        pruned, whole, routes, sizes = [], [], [], []
        while len(sizes) < repeat:
            graph = word_graph(rng, int(target * 0.7))
            if abs(odd_count(graph) - target) > 4:
                continue
            timed = _Timed()
            start = time.process_time()
            plan_routes(graph, {}, stroke_width=4.0, directions={})
            routes.append(time.process_time() - start)
            timed.close()
            (m, seconds), = timed.calls
            sizes.append(m)
            pruned.append(seconds)
            # the same problem with every pair given to blossom (pen ends free here: cost 0)
            ids = sorted(graph.incident)
            where = {n: i for i, n in enumerate(ids)}
            dense = np.zeros((len(ids), len(ids)))
            for b in graph.branches.values():
                i, j = where[b.a], where[b.b]
                if i != j and (dense[i, j] == 0 or b.length < dense[i, j]):
                    dense[i, j] = dense[j, i] = b.length
            odd = [where[n] for n in ids if graph.degree(n) % 2]
            dist = dijkstra(dense, directed=False, indices=odd)[:, odd]
            k = len(odd)
            full = np.zeros((k + 2, k + 2))
            full[:k, :k] = dist
            rows, cols = np.triu_indices(k + 2, 1)
            start = time.process_time()
            _blossom(rows, cols, np.rint(full[rows, cols] * SCALE).astype(np.int64))
            whole.append(time.process_time() - start)
        print(f"   {statistics.median(sizes):9.0f} {len(sizes):6d} {statistics.median(pruned):9.3f} "
              f"{statistics.median(whole):18.3f} {statistics.median(routes):11.3f}")


def drawings(count: int) -> None:
    from benchmarks.sets.cursive import LINES, cursive_drawing
    from benchmarks.common.render import render_truth, to_uint8
    from vectorize import VectorizeOptions, vectorize_image

    longest = sorted(range(len(LINES)), key=lambda i: -len(LINES[i].replace(" ", "")))[:count]
    picks = [cursive_drawing(0, i) for i in longest] + [cursive_drawing(0, 0, text) for text in LONG_LINES]
    print("2. cursive lines, vectorized (CPU s):")
    print(f"   {'line':52s} {'letters':>7s} {'odd nodes':>9s} {'matching':>8s} {'vectorize':>9s} {'share':>6s}")
    vectorize_image(to_uint8(render_truth(picks[0])), VectorizeOptions())  # warm-up: model, imports
    for gt in picks:
        image = to_uint8(render_truth(gt))
        timed = _Timed()
        start = time.process_time()
        vectorize_image(image, VectorizeOptions())
        total = time.process_time() - start
        timed.close()
        matching = sum(s for _, s in timed.calls)
        odd = max((m for m, _ in timed.calls), default=0)
        print(f"   {gt.meta['text'][:52]:52s} {gt.meta['letters']:7d} {odd:9d} {matching:8.3f} {total:9.3f} "
              f"{100 * matching / total:5.1f}%")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--odd", type=int, nargs="+", default=[100], help="odd nodes of the synthetic graphs")
    ap.add_argument("--repeat", type=int, default=5, help="synthetic graphs per size")
    ap.add_argument("--lines", type=int, default=4, help="longest cursive lines to vectorize")
    args = ap.parse_args(argv)
    print(f"route inspection's matching, {time.strftime('%Y-%m-%d %H:%M:%S %Z')}, {os.cpu_count()} CPUs, "
          f"load average {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    synthetic(args.odd, args.repeat)
    drawings(args.lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
