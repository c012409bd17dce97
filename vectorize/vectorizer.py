"""The raster pipeline, stage by stage (paper 3.1-3.4 and 4.5)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from vectorize.axis.clusters import merge_triple_points, straightest_pairs
from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import Simplified, directions, simplify, slots
from vectorize.axis.stem_clusters import merge_stem_clusters, stem_passes
from vectorize.drawing import Drawing
from vectorize.fit.ink_guard import InkGuard, guard_margin
from vectorize.fit.ink_width import edge_offset, ink_widths
from vectorize.fit.retraces import Twin, foot_is_retraced, trimmed_twins, twin_spans
from vectorize.front_stages import front_stages, output_matrix, pixel_frame, refuse_ragged
from vectorize.junctions.classifiers import make_classifier, shipped_pass_scorer
from vectorize.junctions.crossing_point import crossing_point, passes_crossing
from vectorize.junctions.intersections import (Junction, JunctionVerdict, along_line, lone_junctions, ranked_pairings,
                                              sharp_touch)
from vectorize.junctions.junction_ink import own_ink, own_ink_reach
from vectorize.options import InputFrame, VectorizeOptions, VectorizeReport, VectorizeResult
from vectorize.raster.binarize import InkImage
from vectorize.route.retrace_paths import turn_prices, turns_at
from vectorize.route.route_ends import end_costs
from vectorize.route.route_inspection import connect_pairings, cuts_off, plan_routes, shared_bands
from vectorize.route.traversal import Ordering, half_turns, order_strokes, turn_backs
from vectorize.stage_clock import StageClock
from vectorize.stroke import Stroke, lengths

if TYPE_CHECKING:  # the studio's refinement is imported where edits or a session ask for it
    from collections.abc import Callable

    from vectorize.fit.fitting import TracedPoints
    from vectorize.refine.edits import Edits
    from vectorize.refine.refine import Refinement, StageCache

# Share of plausibility of the smoother touching pairing when the classifier says "touch".
SMOOTHER_TOUCH = 0.85
# How sure a verdict may be taken where pairings of equal capped cost are told apart
# (`route_inspection.connect_pairings`): the classifiers' own bound (`_with_geometry`).
EVIDENCE_SURE = 1.0 - 1e-6


def _junctions(graph: MedialGraph, nodes, stroke_width: float) -> list[Junction]:
    result = []
    for node in nodes:
        dirs = directions(graph, node, 2.5 * stroke_width)
        radii = []
        for bid, end in slots(graph, node):
            branch = graph.branches[bid]
            r = branch.radii if end == "a" else branch.radii[::-1]
            pts = branch.points if end == "a" else branch.points[::-1]
            dist = lengths(pts - pts[0])
            band = r[(dist > 1.5 * stroke_width) & (dist < 3.5 * stroke_width)]
            radii.extend(band.tolist())
        width = 2.0 * float(np.median(radii)) if radii else stroke_width
        # The classifier sees only the junction's own ink (`vectorize.junctions.junction_ink`).
        ink = own_ink(graph, node, own_ink_reach(dirs, stroke_width), stroke_width)
        result.append(Junction(center=graph.positions[node].copy(), directions=dirs, width=width,
                               crossing=crossing_point(graph, node, dirs, stroke_width), ink=ink))
    return result


def _with_geometry(image: JunctionVerdict, geometry: JunctionVerdict, sharp: bool = False) -> JunctionVerdict:
    """The CNN's verdict with the branch geometry as independent evidence (log-odds add).

    Where touching would mean sharp turns (a steep crossing, perhaps with a hook nearby that
    confuses the image) geometry is decisive; at a touch or a shallow crossing both
    pairings are smooth, geometry says ~0.5 and the image decides alone. `sharp`
    (`intersections.sharp_touch`): touching would turn a pass sharply where going straight
    does not, which no touch does: the image's evidence for a touch is not taken (the CNN
    never saw a stroke bend at a crossing in training, and reads one as a touch with full
    confidence), its evidence for a crossing is.
    """
    def logit(p: float) -> float:
        p = min(max(p, 1e-4), 1 - 1e-4)
        return float(np.log(p / (1 - p)))

    p = float(1.0 / (1.0 + np.exp(-(logit(image.p_crossing) + logit(geometry.p_crossing)))))
    if sharp and p < geometry.p_crossing:
        return geometry
    agree = (p >= 0.5) == image.is_crossing
    return JunctionVerdict(p_crossing=p, confidence=image.confidence if agree else max(p, 1 - p))


def _pair_through(graph: MedialGraph, nodes, gray: np.ndarray, w: float,
                  options: VectorizeOptions) -> tuple[dict, dict]:
    """Pair the feet of each triple point: by continuation and the image (the pass scorer,
    with the CNN classifier, when its model is installed), by continuation alone otherwise.
    A single line leaves a node undecided where that pairing would cut it in pieces.
    Returns (node -> slot pairs, six-foot node -> the scorer's posterior over its pairings)."""
    if not nodes:
        return {}, {}
    feet = {n: directions(graph, n, 2.5 * w) for n in nodes}
    result = {n: straightest_pairs(d)[0] for n, d in feet.items()}
    six = [n for n in nodes if len(feet[n]) == 6]
    scorer = shipped_pass_scorer() if six and getattr(make_classifier(options.classifier), "name", "") == "cnn" else None
    posterior = {}
    if six and scorer is not None:
        from vectorize.junctions.pass_scorer import scored_pairings

        centers = np.array([graph.positions[n] for n in six])
        for node, (pick, odds) in zip(six, scored_pairings(gray, centers, [feet[n] for n in six], w, scorer)):
            result[node], posterior[node] = pick, odds
    if not options.multi:
        # Passes that cut a piece off the line (`route_inspection.cuts_off`: from one free end
        # to another, as an entry tick and a stem drawn down from one point make when they are
        # collinear) are not how the line went through: the node is not three passes (spikes
        # drawn out and back leave it), and route inspection walks it as an undecided
        # junction, which keeps the line in one piece.
        result = {n: pairs for n, pairs in result.items() if not cuts_off(graph, n, pairs)}
        posterior = {n: odds for n, odds in posterior.items() if n in result}
    return result, posterior


def _pairing_costs(verdict: JunctionVerdict, sure: float = 0.98) -> tuple[float, float, float]:
    """-log plausibility of the three ranked pairings, relative to the first, the verdict taken
    as no surer than `sure` either way."""
    p = float(np.clip(verdict.p_crossing, 1.0 - sure, sure))
    straight, touch_a, touch_b = p, (1 - p) * SMOOTHER_TOUCH, (1 - p) * (1 - SMOOTHER_TOUCH)
    ranked = [straight, touch_a, touch_b] if verdict.is_crossing else [touch_a, straight, touch_b]
    return tuple(float(np.log(ranked[0]) - np.log(x)) for x in ranked)  # type: ignore[return-value]


# Stroke widths. Branches from a crossing to another junction that the route walks twice
# measured 0.77-2.42 widths (9 lengths; the kitten's 1.98) and then 3.05 and up (h and l bases
# whose way in and stem share a band, 4.1, `route_inspection.shared_bands`; stems drawn down
# and back, 12 and up) over the cursive set at seed 1: a longer band keeps its own points.
SHARED_STUB_WIDTHS = 2.5


def _shared_stub_reach(graph: MedialGraph, node: int, stubs: set[int], stroke_width: float) -> float:
    """How far (px) the uncertain zone of a crossing at `node` reaches over its shared stubs
    (`stubs`: branches between two junctions, at most `SHARED_STUB_WIDTHS` long, that the
    route walks twice): to the far junction and half a width past it (where the two passes
    part, their inks still overlap); 0 without such a stub.

    A cursive l or h whose loop closes a stub away from the crossing (the_kitten_ate_the_
    mauled_candy-1-30's "th": the loop's two ends meet 3 px (1.98 widths) above the crossing
    of the way in and the way down): both passes run over the stub, and with the zone
    ending before the far junction each kept both junctions' points, so the fitted passes
    ran together over the stub, 0.1-0.3 px apart, instead of crossing.
    """
    fars = [graph.branches[bid].other(node) for bid, _ in slots(graph, node) if bid in stubs]
    return max((float(np.linalg.norm(graph.positions[far] - graph.positions[node])) + 0.5 * stroke_width
                for far in fars), default=0.0)


def _trace(graph: MedialGraph, simple: Simplified, ordering: Ordering, junctions: dict,
           verdicts: dict, stroke_width: float) -> list[tuple[TracedPoints, bool, list[Twin]]]:
    """Turn branch passes into point lists flagged for filtering (paper 3.4), with the
    stretches each stroke draws twice (`vectorize.fit.retraces`)."""
    from vectorize.fit.fitting import TracedPoints

    # V-spikes: the foot is where both sides' inks merge, its points are uncertain; the
    # sides run straight to the tip. Retraced (T) spikes: the foot is the spike itself,
    # its points are good, and the line turns sharply at both of its ends.
    # V-spikes whose foot runs on far beyond the corner are a line drawn down and back up:
    # there the foot is the centre line both passes follow (`vectorize.fit.retraces`).
    foot_branches = {slots(graph, n)[f][0] for n, f in simple.y_feet.items()
                     if n not in simple.retraced and not foot_is_retraced(graph, n, f, stroke_width)}
    sharp_points = [graph.positions[n] for n in simple.retraced]
    crossing_of = dict(zip(simple.crossings, ordering.choice))
    decided = {**{n: p for n, p in crossing_of.items() if n not in ordering.undecided}, **simple.through}
    # Uncertain zone around each degree-4 node: where the two strokes' inks still overlap.
    stubs = shared_bands(graph, [step for passes in ordering.strokes for step in passes], stroke_width,
                         max_widths=SHARED_STUB_WIDTHS)
    zones = []
    for node in simple.crossings:
        junction = junctions[node]
        d = junction.directions
        cos = max(-float(np.dot(d[a], d[b])) for a, b in crossing_of[node])
        half_angle = np.arccos(np.clip(cos, -1.0, 1.0)) / 2.0
        angle = np.pi / 2 - half_angle  # half the angle between the two crossing lines
        reach = stroke_width / (2.0 * max(np.sin(max(angle, 1e-3)), 1e-3))
        # The shared ink of a merged node (its span) is uncertain too: both strokes' points
        # there lie on one averaged centre line.
        reach = max(reach, graph.spans.get(node, 0.0) + 0.5 * stroke_width)
        if verdicts[node].is_crossing:
            reach = max(reach, _shared_stub_reach(graph, node, stubs, stroke_width))
        reach = float(np.clip(reach, graph.radii[node], 12.0 * stroke_width))
        zones.append((node, reach, verdicts[node].is_crossing))
    for node in simple.through:
        # Three passes cross: their inks overlap about as far as the cluster reached.
        reach = float(np.clip(graph.spans.get(node, 0.0) + stroke_width, graph.radii[node], 12.0 * stroke_width))
        zones.append((node, reach, True))
    result = []
    # Not retraced stretches: a loop (its direction cannot be told from where it starts) and
    # the foot of a V-spike (each side of the V runs to the tip on its own ink).
    not_twins = {bid for bid, b in graph.branches.items() if b.a == b.b} | foot_branches
    # A crossing's stub (`_shared_stub_reach`) is the two crossing passes' shared ink, not one
    # line drawn twice: its points lie in the zone and each pass runs straight through.
    not_twins |= {bid for node, reach, crossing in zones if crossing for bid, _ in slots(graph, node) if bid in stubs}
    zone_nodes = {node for node, _, _ in zones}
    for passes, closed in zip(ordering.strokes, ordering.closed):
        parts, keeps, tips, spans, radii, owners, forks = [], [], [], [], [], [], []
        count = 0  # traced points so far
        # Where the pen turns back at a junction it goes up to the node and returns: its
        # points there are the line, not uncertain ink of passes running through.
        turned = turn_backs(graph, passes, zone_nodes, stroke_width)
        # A turn within one half of a merged node's band turns where its two branches part.
        cut = half_turns(graph, passes)
        for index, step in enumerate(passes):
            branch = graph.branches[step.branch]
            # By end, not by node: a loop starts and ends at the same node.
            points = branch.points if step.start == "a" else branch.points[::-1]
            radius = branch.radii if step.start == "a" else branch.radii[::-1]
            far_node = branch.node(step.end)
            head = 0 if index == 0 else 1 + cut.get(index - 1, 0)
            tail = len(points) - cut.get(index, 0)
            points, radius = points[head:tail], radius[head:tail]
            spans.append((max(count - 1, 0), count + len(points) - 1))
            if not len(points):
                continue
            count += len(points)
            on_foot = step.branch in foot_branches
            # The pen turns back on itself: a cusp (the fit splits there, never loops).
            turns_back = (index + 1 < len(passes) and passes[index + 1].branch == step.branch
                          and passes[index + 1].start != step.start) or index in turned
            tip = np.zeros(len(points), dtype=bool)
            tip[-1] = far_node in simple.y_tips or turns_back or (
                index + 1 < len(passes) and turns_at(graph, decided, step, passes[index + 1]))
            fork = np.zeros(len(points), dtype=bool)
            fork[-1] = graph.degree(far_node) >= 3
            if index == 0:
                fork[0] = graph.degree(branch.node(step.start)) >= 3
            parts.append(points)
            radii.append(radius)
            owners.append(np.full(len(points), index))
            forks.append(fork)
            keeps.append(tip | (not on_foot))
            tips.append(tip)
        twins = twin_spans([p.branch for p in passes], [p.start for p in passes], spans, not_twins)
        if not parts:
            result.append((TracedPoints(xy=np.zeros((0, 2)), keep=np.zeros(0, bool), split=np.zeros(0, bool)),
                           closed, twins))
            continue
        xy, keep, split = np.concatenate(parts), np.concatenate(keeps), np.concatenate(tips)
        if cut:
            twins = trimmed_twins(xy, twins, [spans[i][1] for i in cut])
        for base in sharp_points:
            split[np.all(xy == base, axis=1)] = True
        owner = np.concatenate(owners)
        held = np.ones(len(xy))
        for node, reach, crossing in zones:
            dist = lengths(xy - graph.positions[node])
            turning = [i for i, at in turned.items() if at == node]
            near = (dist < reach) & ~np.isin(owner, turning + [i + 1 for i in turning])
            keep[near] &= crossing & (dist[near] < 1e-6)
            if node in simple.held:
                # A stem cluster's node is placed where its two crossing passes cross (the
                # band they share at its narrowest ink, at its middle, or where their courses
                # either side meet: `stem_clusters`), and its zone is the band's length (20 px
                # and more each way on wide lines). Each pass keeps the node alone in that
                # gap: it stands for the points dropped about it, or the smoothing spends its
                # residual there, and where two passes cross at a shallow angle a pixel beside
                # the node moves their crossing 1 / sin(a) px along the band. Not a crossing
                # `simplify` merged at the middle of the branch between its halves: there the
                # fit bridging a short zone does better (held, EMSTech-R's crossing went 2.4
                # -> 5.3 px off, measured).
                for i in np.flatnonzero(near & keep):
                    held[i] = max(held[i], _run(near & ~keep, i))
        result.append((TracedPoints(xy=xy, keep=keep, split=split, radius=np.concatenate(radii),
                                    junction=np.concatenate(forks), held=held), closed, twins))
    return result


def _run(marked: np.ndarray, at: int) -> int:
    """Points in the run of `marked` ((N,) bool) points next to `at` on both sides, plus `at`."""
    before = marked[:at][::-1]
    after = marked[at + 1:]
    count_before = int(np.argmin(before)) if not before.all() else len(before)
    count_after = int(np.argmin(after)) if not after.all() else len(after)
    return 1 + count_before + count_after


def _orient(stroke: Stroke, closed: bool) -> Stroke:
    """Deterministic direction: open strokes start at the end nearer the top-left corner."""
    if not closed and stroke.end.sum() < stroke.start.sum():
        return stroke.reversed()
    return stroke


class _Solution(NamedTuple):
    graph: MedialGraph
    simple: Simplified
    junctions: dict
    verdicts: dict
    ordering: Ordering
    tried: int


def _order(graph: MedialGraph, ink, options: VectorizeOptions, ends: int, clock: StageClock,
           refine: Refinement | None = None) -> _Solution:
    """Simplify (in place), classify the crossings and traverse, for one count of free ends.

    With `refine`, the user's splits and merges act inside simplification, fixed pairings
    enter the traversal as decisions it may not change, and simplified graphs with their
    verdicts are reused from the session's cache (they depend on no later edit).
    """
    w = ink.stroke_width
    cached = refine.lookup(ends) if refine is not None else None
    if cached is not None:
        graph, simple, junctions, verdicts = cached
    else:
        hooks = refine.simplify_hooks() if refine is not None else {}
        may_cluster = hooks.pop("may_cluster", None)
        through = merge_triple_points(graph, stroke_width=w, may_merge=may_cluster)
        # A stem drawn down and back up through a crossing (an h's base): read as one node too.
        stems = {} if options.multi else merge_stem_clusters(
            graph, stroke_width=w, ends=ends, through=through, may_merge=may_cluster,
            place=lambda trial, node, passes, window=None: passes_crossing(trial, node, passes, w, window))
        simple = simplify(graph, stroke_width=w, multi=options.multi, ends=ends,
                          through={**through, **dict.fromkeys(stems, ())}, **hooks)
        # Paired after simplification: merging crossings next to a triple point renumbers its slots.
        through, posterior = _pair_through(graph, [n for n in simple.through if n not in stems], ink.gray, w, options)
        through.update({n: stem_passes(graph, n, w, tip)[0] for n, tip in stems.items()})
        simple = replace(simple, through=through, through_posterior=posterior,
                         crossings=tuple(n for n in simple.crossings if n not in stems),
                         y_tips=simple.y_tips | set(stems.values()), held=frozenset(stems))
        clock.lap("simplification")
        if options.max_odd_nodes is not None:  # before the crossings' crops and the route
            odd = sum(1 for n, incident in graph.incident.items() if len(incident) % 2 and n not in simple.through)
            refuse_ragged(odd, "loose ends and forks", options, ink.threshold)
        junction_list = _junctions(graph, simple.crossings, w)
        junctions = dict(zip(simple.crossings, junction_list))
        # The whole image is read too only for a confidence that something shows (the studio).
        shown = {"whole_image": options.whole_image_confidence} if options.classifier == "cnn" else {}
        verdict_list = make_classifier(options.classifier).classify(ink.gray, junction_list, w, **shown) \
            if junction_list else []
        if options.classifier == "cnn" and junction_list:
            geometry = make_classifier("geometric").classify(ink.gray, junction_list, w)
            spans = np.array([graph.spans.get(n, 0.0) for n in simple.crossings])
            lone = lone_junctions(np.array([j.center for j in junction_list]), spans, 2.5 * w,
                                  along_line(graph, simple.crossings, 2.5 * w + 2.0 * float(spans.max())))
            verdict_list = [_with_geometry(v, g, sharp_touch(j.directions) and alone)
                            for v, g, j, alone in zip(verdict_list, geometry, junction_list, lone)]
        verdicts = dict(zip(simple.crossings, verdict_list))
        if refine is not None:
            refine.store(ends, (graph, simple, junctions, verdicts))
    clock.lap("classification")
    if refine is not None:
        simple = refine.fix_passes(graph, simple)
    ranked = {n: ranked_pairings(junctions[n], verdicts[n]) for n in simple.crossings}
    costs = {n: _pairing_costs(verdicts[n]) for n in simple.crossings}
    evidence = {n: _pairing_costs(verdicts[n], EVIDENCE_SURE) for n in simple.crossings}
    if refine is not None:
        refine.fix_pairings(junctions, ranked, costs)
    if options.multi:
        ordering, tried = order_strokes(graph, simple, ranked, costs, stroke_width=w)
    else:
        ordering, tried = _single_route(graph, simple, ranked, costs, w, evidence,
                                        refine.start_ends(graph) if refine is not None else None,
                                        refine.route_weights(graph) if refine is not None else None)
    clock.lap("traversal")
    return _Solution(graph, simple, junctions, verdicts, ordering, tried)


def _single_route(graph: MedialGraph, simple: Simplified, ranked: dict, costs: dict,
                  w: float, evidence: dict, start_at: dict | None = None, weight: dict | None = None) -> tuple[Ordering, int]:
    """Single-line mode: one stroke over the whole (connected) graph, retracing the least.
    start_at: node -> end cost (px) that overrides the rule (a user's start edit); weight:
    branch id -> factor on its retrace cost (a user's twice / once edits)."""
    pairing, tried = connect_pairings(graph, ranked, costs, fixed=simple.through, evidence=evidence)
    dirs = {n: directions(graph, n, 2.5 * w) for n in graph.incident if graph.degree(n) >= 3}
    end_cost = {**end_costs(graph, simple, dirs, w), **(start_at or {})}
    routes = plan_routes(graph, {**simple.through, **pairing}, stroke_width=w, directions=dirs, end_cost=end_cost,
                         weight=weight, turn_price=turn_prices(ranked, costs, pairing, w))
    choice = tuple(pairing.get(n, ranked[n][0]) for n in simple.crossings)
    return Ordering(tuple(r.passes for r in routes), tuple(r.closed for r in routes), choice,
                    sum(r.odd_nodes for r in routes), tuple(n for n in simple.crossings if n not in pairing)), tried


def run_pipeline(image: np.ndarray, options: VectorizeOptions, *,
                 frame: InputFrame | None = None, edits: Edits | None = None,
                 cache: StageCache | None = None, binarized: Callable[[], InkImage] | None = None) -> VectorizeResult:
    """Vectorize `image`; the drawing comes out in `frame` (default: the image's pixels).

    edits: the user's corrections (`vectorize.refine.edits`); cache: a `StageCache` kept between
    calls on the same image, so that an edit re-runs only the stages after it. binarized:
    gives the binarize stage's `InkImage` of this image at these options, computed elsewhere
    (`pipeline.binarize_beside`); not with edits or a cache.
    """
    clock = StageClock(cache.checkpoint if cache is not None else None)
    shape = np.asarray(image).shape
    if frame is None:
        frame = pixel_frame(image)
    refining = edits is not None or cache is not None
    if refining and binarized is not None:
        raise ValueError("a binarize stage computed elsewhere cannot be refined (edits or a cache)")
    if refining:
        # Only the studio and --edits refine: a plain run never imports (or compiles) it.
        from vectorize.refine.edits import Edits
        from vectorize.refine.refine import Refinement, StageCache

        edits = edits if edits is not None else Edits()
        options = edits.applied_to(options)
        cache = cache if cache is not None else StageCache()
        front = cache.front_for(image, options, lambda stages: front_stages(image, options, clock, stages, frame, edits),
                                edits)
    else:
        front = front_stages(image, options, clock, binarized=binarized)
    ink, rings, graph, bridges, dropped, unbridged = front
    w = ink.stroke_width
    scale = ink.scale * frame.scale  # working px per output unit
    matrix = output_matrix(ink.scale, frame)
    refine = Refinement(edits, cache, matrix, options, w) if refining else None
    if refine is not None:
        refine.gaps_kept_open(unbridged)
    stages = {"ink": ink, "rings": rings, "pruned": graph.copy()} if options.keep_stages else None
    # A single line has two free ends, or none when it closes: free ends beyond those are
    # spikes drawn out and back. Try the open reading first, the closed one if it fails.
    readings = (2,) if options.multi else (2, 0)
    # A session's earlier answer for the same edits up to traversal (undo, start, reverse).
    solved = refine.solved() if refine is not None else None
    best = solved[0] if solved is not None else None
    for ends in readings if solved is None else ():
        attempt = _order(graph.copy() if len(readings) > 1 or refining else graph, ink, options, ends, clock, refine)
        if best is None or len(attempt.ordering.strokes) < len(best.ordering.strokes):
            best = attempt
        if len(best.ordering.strokes) <= 1:
            break
    graph, simple, junctions, verdicts, ordering, tried = best

    # Smoothing allowance: the medial axis wobbles by ~0.07 px per px of stroke width (pixel
    # grid, anti-aliasing); fitting tighter follows that wobble, looser cuts corners.
    sigma = float(np.clip(0.065 * w, 0.15, 0.8))
    guard = InkGuard(graph, ink.gray, ink.threshold, margin=guard_margin(w), rings=rings) if solved is None else None
    edge = edge_offset(ink.gray, ink.ink, rings, ink.threshold, w) if solved is None else 0.0
    blobs = np.array([[*graph.positions[n], graph.radii[n]] for n, incident in graph.incident.items()
                      if len(incident) >= 3]).reshape(-1, 3)
    strokes = list(solved[1]) if solved is not None else []
    from vectorize.fit.fitting import fit_stroke

    for traced, closed, twins in _trace(graph, simple, ordering, junctions, verdicts, w) if solved is None else ():
        if len(traced) < 2:
            continue
        fitted = fit_stroke(traced, closed=closed, sigma=sigma, stroke_width=w, guard=guard, twins=tuple(twins))
        fitted = fitted.with_widths(ink_widths(fitted, traced.xy, traced.radius, traced.keep, w, edge, blobs))
        strokes.append(_orient(fitted, closed))
    if refine is not None and solved is None:
        refine.keep_solved(best, strokes)
    strokes = [s for s in strokes if s.length > 0.5 * w or len(strokes) == 1]
    strokes.sort(key=lambda s: (round(float(s.start.sum()) / (4 * w)), float(s.start[0])))
    clock.lap("fitting")

    # Back to the input's frame: original image pixels, or the SVG's user units.
    drawing = Drawing(tuple(s.transformed(matrix) for s in strokes), frame.width, frame.height, "px", w / scale)
    if refine is not None:
        drawing = refine.orient(drawing)

    warnings = []
    if ink.scale < 1.0 or frame.reduced_from is not None:
        w0, h0 = frame.reduced_from or (shape[1], shape[0])
        warnings.append(f"image is {w0}x{h0} px: downscaled to {ink.gray.shape[1]}x{ink.gray.shape[0]} to vectorize")
    if ink.frame:
        warnings.append("a dark frame along the image edge (table, scanner lid) was ignored")
    if dropped:
        warnings.append(f"{dropped} separate ink piece(s) dropped: a single-line drawing keeps only the largest"
                        " (use --multi to keep them all)")
    if simple.unresolved:
        warnings.append(f"{len(simple.unresolved)} junction(s) where three or more strokes seem to meet:"
                        " they are not resolved and the order there may be wrong")
    if refine is not None:
        warnings.extend(refine.unmatched() + refine.unheeded(best))
    if not options.multi and len(strokes) > 1:
        warnings.append(f"the line could not be followed in one stroke: {len(strokes)} strokes")
    report = VectorizeReport(
        strokes=len(strokes), intersections=len(simple.crossings), y_junctions=len(simple.y_feet),
        dropped_components=dropped, gaps_bridged=len(bridges), high_degree_junctions=len(simple.unresolved),
        retries=tried - 1, odd_nodes=ordering.odd_nodes,
        scale=scale, stroke_width=w / scale, threshold=float(ink.threshold), warnings=tuple(warnings),
        seconds=clock.seconds,
        cpu_seconds=clock.cpu_seconds)
    if stages is not None:
        stages.update(simplified=graph, simple=simple, junctions=junctions, verdicts=verdicts,
                      ordering=ordering, working_strokes=strokes)
    view = refine.graph_view(best, bridges, unbridged) if refine is not None else None
    return VectorizeResult(drawing, report, stages, view)
