"""Route-inspection figures of a benchmark run: how large the matchings were and how close
each output came to the shortest single line that draws its ink.

- odd nodes (ink): odd-degree junctions of the ground truth's ink graph (`metrics.ink`), the
  size of the matching any route inspection of that drawing solves;
- odd nodes (vectorizer): those the vectorizer's route inspection matched
  (`VectorizeReport.odd_nodes`, on its own branch graph);
- route ratio: the output's total length over the minimum traversal of the ground truth's
  ink graph (`metrics.ink.min_traversal_length`, networkx's blossom on that graph: computed
  independently of the vectorizer). "within 2 %": ratio <= 1.02;
- drawn ratio: the output's length over the ground-truth pen path's; "> 5 %": outputs longer
  than the drawn line by more than 5 % (a run-away retrace).
"""

from __future__ import annotations

import statistics

import numpy as np

from benchmarks.metrics.ink import ink_graph, min_traversal_length

ROUTE_SLACK = 0.02  # an output within this share above the minimum traversal counts as on the route optimum
DRAWN_SLACK = 0.05  # an output longer than the drawn line by more than this share retraced too much
FLATTEN = 0.05  # px: a ground truth's flattening for its ink graph when the set did not give one


def ground_truth_route(gt) -> tuple[int, float]:
    """(odd nodes, minimum traversal px) of the ground truth's ink graph: from its meta where the
    set measured them (on the pen path before jitter, or with near-retraces snapped), else from
    its stroke flattened."""
    meta = gt.meta
    if "route_min" in meta and "odd_nodes" in meta:
        return int(meta["odd_nodes"]), float(meta["route_min"])
    graph = ink_graph(gt.stroke.flatten(FLATTEN))
    odd = int(np.count_nonzero(graph.degrees % 2))
    return int(meta.get("odd_nodes", odd)), float(meta.get("route_min", min_traversal_length(graph)))


def route_row(gt, output, report) -> dict:
    """The per-drawing columns (module doc)."""
    odd_gt, route_min = ground_truth_route(gt)
    return {"odd_nodes_gt": odd_gt, "odd_nodes": getattr(report, "odd_nodes", float("nan")),
            "route_min": route_min, "route_ratio": output.length / route_min,
            "drawn_ratio": output.length / gt.drawing.length}


def _spread(values: list) -> str:
    values = [v for v in values if v == v]
    if not values:
        return "-"
    return f"{min(values):.0f} / {statistics.median(values):.0f} / {max(values):.0f}"


def print_route_figures(rows: list[dict]) -> None:
    """Per set and classifier: odd-node counts (min / median / max), the share of outputs within
    2 % of the minimum traversal, the largest route ratio, and outputs over 5 % longer than drawn."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        if not r.get("error") and "route_ratio" in r:
            groups.setdefault((r["set"], r["classifier"]), []).append(r)
    if not groups:
        return
    print()
    print("route inspection (odd nodes min / median / max; route ratio = output length / minimum traversal of the "
          "ground truth's ink graph, networkx blossom):")
    print(f"  {'set':16s} {'classifier':10s} {'n':>4s} {'odd nodes (ink)':>16s} {'odd (vectorizer)':>17s} {'> 14':>5s} "
          f"{'within 2 %':>10s} {'max ratio':>9s} {'> 5 % drawn':>11s}")
    for (name, classifier), group in groups.items():
        ratios = [r["route_ratio"] for r in group]
        within = 100.0 * sum(x <= 1.0 + ROUTE_SLACK for x in ratios) / len(group)
        over = sum(r["drawn_ratio"] > 1.0 + DRAWN_SLACK for r in group)
        large = sum(r["odd_nodes"] > 14 for r in group if r["odd_nodes"] == r["odd_nodes"])
        print(f"  {name:16s} {classifier:10s} {len(group):4d} {_spread([r['odd_nodes_gt'] for r in group]):>16s} "
              f"{_spread([r['odd_nodes'] for r in group]):>17s} {large:5d} {within:9.1f}% {max(ratios):9.3f} "
              f"{over:11d}")
    outliers = [r for g in groups.values() for r in g if r["route_ratio"] > 1.0 + ROUTE_SLACK]
    for r in sorted(outliers, key=lambda r: -r["route_ratio"])[:10]:
        print(f"    over 2 %: {r['set']}/{r['classifier']}/{r['name']}: {r['out_length']:.0f} px against a minimum of "
              f"{r['route_min']:.0f} px (ratio {r['route_ratio']:.3f}; drawn {r['drawn_ratio']:.3f})")
