"""Applying a user's edits (`vectorize.refine.edits`) at the pipeline's stage boundaries, and the
view of the graph they act on.

`StageCache` keeps what earlier stages made for one image, keyed by what they depend on,
so that an edit re-runs only the stages after it: a pairing or a start re-runs traversal
and fitting; a split or merge re-runs simplification and classification as well; threshold,
blur and mode re-run everything. The cached path makes the same calls on the same inputs
as a fresh run, so both give the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import shapely

from onestroke.errors import Cancelled
from vectorize.axis.simplify import _merge, directions
from vectorize.drawing import Drawing
from vectorize.junctions.intersections import crossing_pairing, touching_pairings
from vectorize.refine.edits import PAIRINGS, Edits
from vectorize.refine.pass_choices import as_angles, chance_of, foot_angles, normal, pass_options, slots_of

# Route inspection's factor on a branch's length where the user said the line goes back
# over it ("twice": nearly free) or does not ("once": only if nothing else joins the ends).
RETRACE_WEIGHT = {"twice": 1e-3, "once": 1e4}
# Cached entries per stage: a session goes back and forth between a few states (undo), and
# the studio adds the four neighbouring slider values of each state it answers.
KEEP = 20


# Entries of the image-sized stages (a working gray image, an ink image, ~4 MB each at
# 1000 px): the last few slider positions and their neighbours.
KEEP_IMAGES = 8


class StageCache:
    """Results of the early stages for one image (the studio keeps one per drawing).

    gray: (max_size,) -> (gray, scale) of `vectorize.raster.binarize.downscaled_gray` (neither
    blur nor threshold change it); paper: (blur, max_size) -> (gray, scale) of
    `vectorize.raster.binarize.paper_gray` (the threshold does not change it); axis: (threshold,
    blur, max_size) -> (ink, rings, medial graph before pruning) (the mode does not change
    them); front: `front_key` -> the pruned (and in single-line mode bridged) graph with its
    ink (the "unbridge" edits change it too).

    cancel: None or a callable the pipeline asks between stages; when it says True the run
    stops with `onestroke.errors.Cancelled`. Every entry is stored only once its stage has
    finished, so a stopped run leaves the cache as a finished one would have up to there.
    """

    def __init__(self) -> None:
        self.loaded = None  # ((path, max_size), (image, frame)) of the last file read
        self.gray: dict = {}
        self.paper: dict = {}
        self.axis: dict = {}
        self.front: dict = {}
        self.simplified: dict = {}
        self.solved: dict = {}
        self._image = None
        self.cancel = None

    def checkpoint(self) -> None:
        """Raise `Cancelled` if the caller no longer wants this run (see `cancel`)."""
        if self.cancel is not None and self.cancel():
            raise Cancelled("a newer request replaced this one")

    def front_for(self, image, options, compute, edits: Edits | None = None):
        """Binarization to gap bridging for these options (and the edits' "unbridge"
        positions), computed once; compute(cache) may use `stage` for the parts that fewer
        options change."""
        if self._image is not image:
            for store in (self.gray, self.paper, self.axis, self.front, self.simplified, self.solved):
                store.clear()
            self._image = image
        key = front_key(options, edits)
        if key not in self.front:
            _bounded_put(self.front, key, compute(self))
        return self.front[key]

    def stage(self, name: str, key: tuple, compute):
        """The cached result of stage `name` ("gray", "paper" or "axis") for `key`, computed once."""
        store = getattr(self, name)
        if key not in store:
            _bounded_put(store, key, compute(), KEEP_IMAGES)
        return store[key]


def front_key(options, edits: Edits | None = None) -> tuple:
    """What binarization to gap bridging depend on: threshold, blur, mode, size and, in
    single-line mode, the gaps the user kept open (with the match radius)."""
    key = (options.threshold, options.blur, options.multi, options.max_size)
    gaps = () if edits is None or options.multi else tuple(e.at for e in edits.of("unbridge"))
    return key + (gaps, edits.tolerance) if gaps else key


def to_working(matrix: np.ndarray, at) -> np.ndarray:
    """(x, y) output px -> (2,) working px, for `matrix` 2x3 working px -> output px."""
    return (np.asarray(at, dtype=float) - matrix[:, 2]) * (1.0 / float(matrix[0, 0]))


def to_output(matrix: np.ndarray, xy) -> tuple[float, float]:
    """(2,) working px -> (x, y) output px, rounded to 0.001 px (as the page gets it)."""
    out = matrix[:, :2] @ np.asarray(xy, dtype=float) + matrix[:, 2]
    return (round(float(out[0]), 3), round(float(out[1]), 3))


class Unbridging:
    """The "unbridge" edits as gap bridging asks for them (`vectorize.axis.gaps.bridge_gaps`'s
    `refuse`): a bridge passing within the edits' tolerance of an edit's position is not made.

    matrix: 2x3 working px -> output px. refused: (edit position, (end, end)) of each bridge
    refused, output px (the page shows them, to put them back)."""

    def __init__(self, edits: Edits, matrix: np.ndarray) -> None:
        self.matrix = matrix
        self.points = [(e.at, shapely.Point(to_working(matrix, e.at))) for e in edits.of("unbridge")]
        self.tol = edits.tolerance * (1.0 / float(matrix[0, 0]))
        self.refused: list = []

    def __call__(self, a: np.ndarray, b: np.ndarray) -> bool:
        gap = shapely.LineString([a, b])
        for at, point in self.points:
            if gap.distance(point) <= self.tol:
                self.refused.append((at, (to_output(self.matrix, a), to_output(self.matrix, b))))
                return True
        return False


def _bounded_put(store: dict, key, value, keep: int = KEEP) -> None:
    while len(store) >= keep:
        store.pop(next(iter(store)))
    store[key] = value


@dataclass(frozen=True)
class JunctionInfo:
    """A node the page shows. id: node id of this run (not stable across runs: edits use
    `at`); at: (x, y) output px; degree; role: "crossing" (degree 4), "triple" (three passes
    through one point), "y" (a spike's junction), "end" (a stroke ends on a line) or
    "unresolved"; for crossings: decision (one of `PAIRINGS`), p_crossing and confidence of
    the classifier, fixed (by an edit) and merged (made from two degree-3 nodes: can be
    split); for triple points: passes (the pairing drawn, as pairs of branch directions in
    degrees, `vectorize.refine.pass_choices`), confidence (the pass scorer's posterior, None when
    continuation alone decided) and options (the pairings that keep the line one stroke,
    likeliest first: each {"passes", "p"})."""

    id: int
    at: tuple[float, float]
    degree: int
    role: str
    decision: str | None = None
    p_crossing: float | None = None
    confidence: float | None = None
    fixed: bool = False
    merged: bool = False
    passes: tuple | None = None
    options: tuple | None = None


@dataclass(frozen=True)
class BranchInfo:
    """A branch joining two degree-3 nodes (a merge candidate): at is its middle point
    (x, y) output px, length in output px; nodes: the ids of the two nodes it joins (the
    `JunctionInfo.id`s: the page offers "merge" at an unresolved junction by them)."""

    id: int
    at: tuple[float, float]
    length: float
    nodes: tuple[int, int] = ()


@dataclass(frozen=True)
class GraphView:
    """The simplified graph of the chosen reading, in output px. retraces: the stretches the
    line draws twice (route inspection's doubled branches, spikes out and back), each
    {"at": middle point, "length": px, "points": (M, 2) its centre line}."""

    junctions: tuple[JunctionInfo, ...]
    branches: tuple[BranchInfo, ...]
    retraces: tuple[dict, ...] = ()
    ends: tuple[tuple[float, float], ...] = ()  # the free ends of the line (where it may start)
    bridges: tuple[tuple[tuple[float, float], tuple[float, float]], ...] = ()  # pen gaps joined: their ends
    unbridged: tuple[tuple[tuple[float, float], tuple[float, float]], ...] = ()  # gaps kept open by an edit

    def to_dict(self) -> dict:
        return {"junctions": [vars(j) for j in self.junctions], "branches": [vars(b) for b in self.branches],
                "retraces": list(self.retraces), "ends": [list(e) for e in self.ends],
                "bridges": [[list(a), list(b)] for a, b in self.bridges],
                "unbridged": [[list(a), list(b)] for a, b in self.unbridged]}


def _pairings(directions: np.ndarray) -> tuple:
    """The node's three pairings in the order of `PAIRINGS`: crossing, then the touchings."""
    return (crossing_pairing(directions),) + touching_pairings(directions)


def pairing_kind(directions: np.ndarray, pairing) -> str:
    """Which of `PAIRINGS` this pairing of a degree-4 node's slots is."""
    normal = tuple(sorted(tuple(sorted(p)) for p in pairing))
    for kind, option in zip(PAIRINGS, _pairings(directions)):
        if tuple(option) == normal:
            return kind
    return PAIRINGS[0]


def pairing_of(directions: np.ndarray, kind: str):
    """The pairing of slots that `kind` names at a node with these branch directions."""
    return _pairings(directions)[PAIRINGS.index(kind)]


class Refinement:
    """One run's edits, in the working image's pixels, with the hooks the stages call.

    matrix: 2x3 working px -> output px; options: the run's VectorizeOptions (edits
    applied); stroke_width: working px.
    """

    def __init__(self, edits: Edits, cache: StageCache, matrix: np.ndarray, options, stroke_width: float) -> None:
        self.edits = edits
        self.cache = cache
        self.matrix = matrix
        self.options = options
        self.scale = 1.0 / float(matrix[0, 0])  # working px per output px
        self.tol = edits.tolerance * self.scale
        self.w = stroke_width
        self.hits: set[int] = set()
        self.fixed: dict[int, str] = {}
        self._index = {id(e): i for i, e in enumerate(edits.items)}

    def to_working(self, at) -> np.ndarray:
        return to_working(self.matrix, at)

    def to_output(self, xy) -> tuple[float, float]:
        return to_output(self.matrix, xy)

    def gaps_kept_open(self, refused) -> None:
        """Count the "unbridge" edits as heeded: those that refused a bridge (`refused`, as
        `Unbridging.refused`), and all of them in multi-stroke mode, which bridges nothing."""
        done = {at for at, _ in refused}
        for edit in self.edits.of("unbridge"):
            if self.options.multi or edit.at in done:
                self.hits.add(self._index[id(edit)])

    # -- simplification ------------------------------------------------------------
    def simplify_key(self, ends: int) -> tuple:
        graph_edits = tuple((e.kind, e.at) for e in self.edits.of("split", "merge"))
        return (front_key(self.options, self.edits), ends, self.options.classifier, self.edits.tolerance, graph_edits)

    def lookup(self, ends: int):
        hit = self.cache.simplified.get(self.simplify_key(ends))
        if hit is None:
            return None
        *solution, hits = hit
        self._recall(hits)
        return tuple(solution)

    def store(self, ends: int, solution: tuple) -> None:
        _bounded_put(self.cache.simplified, self.simplify_key(ends), (*solution, self._heeded("split", "merge")))

    # A cached stage keeps which edits it acted on by what they say, not by their place in
    # the list: the same splits after a different first edit share the entry (its key).
    def _heeded(self, *kinds: str) -> frozenset:
        return frozenset(_said(e) for e in self.edits.of(*kinds) if self._index[id(e)] in self.hits)

    def _recall(self, heeded: frozenset) -> None:
        self.hits |= {i for i, e in enumerate(self.edits.items) if _said(e) in heeded}

    def simplify_hooks(self) -> dict:
        """Keyword hooks for `simplify`: splits refuse merges, merges collapse branches."""
        splits = [(self._index[id(e)], self.to_working(e.at)) for e in self.edits.of("split")]
        merges = [(self._index[id(e)], self.to_working(e.at)) for e in self.edits.of("merge")]
        hooks = {}
        if splits:
            # A split at a triple point keeps its cluster apart and is then spent: the
            # cluster's junctions pair up as crossings, as anywhere else.
            spent: set[int] = set()

            def refuse(branch, exclude: set[int]) -> int | None:
                for index, point in splits:
                    if index not in exclude and np.min(np.linalg.norm(branch.points - point, axis=1)) <= self.tol:
                        self.hits.add(index)
                        return index
                return None

            def may_cluster(branch) -> bool:
                index = refuse(branch, set())
                if index is not None:
                    spent.add(index)
                return index is None

            hooks["may_cluster"] = may_cluster
            hooks["may_merge"] = lambda branch: refuse(branch, spent) is None
        if merges:
            def after_merging(graph) -> int:
                done = 0
                for index, point in merges:
                    bid = _nearest_branch(graph, point, self.tol, eligible=lambda branch: _mergeable(graph, branch))
                    if bid is not None:
                        _merge(graph, graph.branches[bid].a, graph.branches[bid].b, bid)
                        self.hits.add(index)
                        done += 1
                return done
            hooks["after_merging"] = after_merging
        return hooks

    # -- traversal and fitting -------------------------------------------------------
    def _solved_key(self) -> tuple:
        pairings = tuple((e.at, e.pairing, e.passes) for e in self.edits.of("pairing", "passes"))
        retraces = tuple((e.kind, e.at) for e in self.edits.of("twice", "once"))
        return (self.simplify_key(-1), pairings, self._start(), retraces)

    def _start(self):
        """The last start edit's position: where the line begins (it may change the route)."""
        starts = self.edits.of("start")
        return starts[-1].at if starts else None

    def start_ends(self, graph) -> dict:
        """node -> end cost for the route: the free end at the last start edit (a tip the
        line now passes, such as a stem's drawn down and back up) must be an end of it."""
        at = self._start()
        ends = [n for n, incident in graph.incident.items() if len(incident) == 1]
        if at is None or not ends:
            return {}
        dist = np.linalg.norm(np.array([graph.positions[n] for n in ends]) - self.to_working(at), axis=1)
        k = int(np.argmin(dist))
        # Far below any retraced length: the matching leaves this node unpaired.
        return {ends[k]: -1e9} if dist[k] <= self.tol + self.w else {}

    def route_weights(self, graph) -> dict:
        """branch id -> factor on its length for route inspection: small where the user wants
        the line to go back over a branch ("twice"), large where not ("once"); the last edit
        on a branch wins."""
        weights = {}
        edits = self.edits.of("twice", "once")
        nearest = _nearest_branches(graph, [self.to_working(edit.at) for edit in edits], self.tol + self.w)
        for edit, found in zip(edits, nearest):
            if found is not None:
                weights[found] = RETRACE_WEIGHT[edit.kind]
                self.hits.add(self._index[id(edit)])
        return weights

    def solved(self):
        """(best solution, fitted working strokes) of an earlier run with the same edits up to
        traversal, or None."""
        hit = self.cache.solved.get(self._solved_key())
        if hit is None:
            return None
        best, strokes, hits, fixed = hit
        self._recall(hits)
        self.fixed = dict(fixed)
        return best, strokes

    def keep_solved(self, best, strokes) -> None:
        early = self._heeded("split", "merge", "pairing", "passes", "twice", "once")
        _bounded_put(self.cache.solved, self._solved_key(), (best, tuple(strokes), early, dict(self.fixed)))

    def fix_passes(self, graph, simple):
        """`simple` with the triple points' pairings the user chose (`passes` edits)."""
        self.fixed = {}
        edits = self.edits.of("passes")
        if not edits or not simple.through:
            return simple
        through = dict(simple.through)
        nodes = list(through)
        centers = np.array([graph.positions[n] for n in nodes])
        for edit in edits:
            dist = np.linalg.norm(centers - self.to_working(edit.at), axis=1)
            node = nodes[int(np.argmin(dist))]
            pairs = slots_of(edit.passes, foot_angles(directions(graph, node, 2.5 * self.w)))
            if dist.min() <= self.tol and pairs is not None:
                through[node] = pairs
                self.fixed[node] = "passes"
                self.hits.add(self._index[id(edit)])
        return replace(simple, through=through)

    def fix_pairings(self, junctions: dict, ranked: dict, costs: dict) -> None:
        """Pairings the user chose become the only choice at their node (in place)."""
        nodes = list(junctions)
        if not nodes:
            return
        centers = np.array([junctions[n].center for n in nodes])
        for edit in self.edits.of("pairing"):
            dist = np.linalg.norm(centers - self.to_working(edit.at), axis=1)
            k = int(np.argmin(dist))
            if dist[k] > self.tol:
                continue
            node = nodes[k]
            ranked[node] = (pairing_of(junctions[node].directions, edit.pairing),)
            costs[node] = (0.0,)
            self.fixed[node] = edit.pairing
            self.hits.add(self._index[id(edit)])

    # -- after fitting ---------------------------------------------------------------
    def orient(self, drawing: Drawing) -> Drawing:
        """Apply the start and reverse edits to the finished drawing (output px)."""
        strokes = list(drawing.strokes)
        tol = self.edits.tolerance + drawing.stroke_width
        # Each stroke flattened once per direction (a reverse edit flips it back and forth):
        # thousands of edits would otherwise flatten every stroke for each of them.
        flat: dict[bytes, np.ndarray] = {}

        def polyline(stroke) -> np.ndarray:
            key = stroke.control.tobytes()
            if key not in flat:
                flat[key] = stroke.flatten(0.5)
            return flat[key]

        for edit in self.edits.of("reverse", "start"):
            at = np.asarray(edit.at)
            if edit.kind == "reverse":
                dists = [float(np.min(np.linalg.norm(polyline(s) - at, axis=1))) for s in strokes]
                k = int(np.argmin(dists)) if dists else -1
                if k >= 0 and dists[k] <= tol:
                    strokes[k] = strokes[k].reversed()
                    self.hits.add(self._index[id(edit)])
                continue
            ends = [(float(np.linalg.norm(s.start - at)), k, False) for k, s in enumerate(strokes) if not s.is_closed]
            ends += [(float(np.linalg.norm(s.end - at)), k, True) for k, s in enumerate(strokes) if not s.is_closed]
            if not ends or min(ends)[0] > tol:
                continue
            _, k, flip = min(ends)
            stroke = strokes.pop(k)
            strokes.insert(0, stroke.reversed() if flip else stroke)
            self.hits.add(self._index[id(edit)])
        return drawing.with_strokes(strokes)

    def unheeded(self, solution) -> list[str]:
        """One warning per "once" edit whose branch the line still draws twice (every other
        way to join the ends that retrace joins is marked "once" too, or there is none), and
        per "twice" edit whose branch it still draws once (route inspection goes back over a
        branch only on a path joining two odd nodes, and no cheapest one runs there, or the
        start chosen at that branch's tip forbids it): a click that changes nothing says why."""
        count = _pass_counts(solution)
        result = []
        edits = self.edits.of("once", "twice")
        nearest = _nearest_branches(solution.graph, [self.to_working(edit.at) for edit in edits], self.tol + self.w)
        for edit, bid in zip(edits, nearest):
            if bid is None:
                continue
            where = f"the stretch at {edit.at[0]:.0f}, {edit.at[1]:.0f}"
            if edit.kind == "once" and count.get(bid, 0) > 1:
                result.append(f"{where} is still drawn twice: one line over the drawing found no way around it")
            if edit.kind == "twice" and count.get(bid, 0) < 2:
                result.append(f"{where} is still drawn once: the line goes back over a stretch only where "
                              "that is its shortest way on to the rest of the drawing, and it is not here")
        return result

    def unmatched(self) -> list[str]:
        """One warning per edit that found nothing to act on; "twice" and "once" in
        multi-stroke mode, which draws no route over the whole drawing, act on nothing by
        their mode, wherever they are (not "matched nothing": the stretch may be right there)."""
        def said(i, e):
            head = f"edit {i + 1} ({e.kind} at {e.at[0]:.0f}, {e.at[1]:.0f})"
            if self.options.multi and e.kind in ("twice", "once"):
                return f"{head} acts in single-line mode only and was skipped"
            return f"{head} matched nothing within {self.edits.tolerance:g} px and was skipped"
        return [said(i, e) for i, e in enumerate(self.edits.items) if i not in self.hits]

    # -- the page's view -------------------------------------------------------------
    def graph_view(self, solution, bridges=(), refused=()) -> GraphView:
        """What the page shows of `solution`; bridges: the pen gaps bridged (working px);
        refused: the gaps kept open by an edit (`Unbridging.refused`)."""
        graph, simple = solution.graph, solution.simple
        choice = dict(zip(simple.crossings, solution.ordering.choice))
        nodes = []
        for node in sorted(graph.incident):
            degree = graph.degree(node)
            if node in simple.through:
                nodes.append(self._triple_info(solution, node, choice))
            elif node in simple.crossings:
                junction, verdict = solution.junctions[node], solution.verdicts[node]
                nodes.append(JunctionInfo(
                    node, self.to_output(graph.positions[node]), degree, "crossing",
                    decision=pairing_kind(junction.directions, choice[node]),
                    p_crossing=round(float(verdict.p_crossing), 4), confidence=round(float(verdict.confidence), 4),
                    fixed=node in self.fixed, merged=graph.spans.get(node, 0.0) > 0))
            elif degree >= 3:
                role = "y" if node in simple.y_feet else "end" if node in simple.t_ends and node not in simple.unresolved \
                    else "unresolved"
                nodes.append(JunctionInfo(node, self.to_output(graph.positions[node]), degree, role))
        branches = []
        for bid, branch in sorted(graph.branches.items()):
            if _mergeable(graph, branch):
                middle = branch.points[len(branch.points) // 2]
                branches.append(BranchInfo(bid, self.to_output(middle), round(branch.length / self.scale, 3),
                                           (int(branch.a), int(branch.b))))
        ends = tuple(self.to_output(graph.positions[n]) for n in sorted(graph.incident) if graph.degree(n) == 1)
        gaps = tuple((self.to_output(a), self.to_output(b)) for a, b in bridges)
        return GraphView(tuple(nodes), tuple(branches), self._retraces(solution), ends, gaps,
                         tuple(pair for _, pair in refused))

    def _retraces(self, solution) -> tuple[dict, ...]:
        graph = solution.graph
        count = _pass_counts(solution)
        result = []
        for bid in sorted(b for b, n in count.items() if n > 1):
            points = graph.branches[bid].points
            step = max(1, len(points) // 40)  # a few dozen points draw it on the page
            line = np.vstack([points[::step], points[-1:]])
            result.append({"at": self.to_output(points[len(points) // 2]),
                           "length": round(graph.branches[bid].length / self.scale, 1),
                           "points": [self.to_output(p) for p in line]})
        return tuple(result)

    def _triple_info(self, solution, node: int, choice: dict) -> JunctionInfo:
        graph, simple = solution.graph, solution.simple
        dirs = directions(graph, node, 2.5 * self.w)
        angles = foot_angles(dirs)
        decided = {**choice, **{n: p for n, p in simple.through.items() if n != node}}
        options = pass_options(graph, node, dirs, simple.through_posterior.get(node), decided,
                               one_piece=not self.options.multi)
        drawn = normal(simple.through[node])
        return JunctionInfo(node, self.to_output(graph.positions[node]), graph.degree(node), "triple",
                            decision="passes", confidence=chance_of(drawn, simple.through_posterior.get(node)),
                            fixed=node in self.fixed, merged=True, passes=tuple(map(tuple, as_angles(drawn, angles))),
                            options=tuple({"passes": as_angles(p, angles), "p": q} for p, q in options))


def _said(edit) -> tuple:
    """What an edit says (kind, place and choice): equal for equal edits."""
    return (edit.kind, edit.at, edit.pairing, edit.passes)


def _pass_counts(solution) -> dict[int, int]:
    """branch id -> how many times the solution's strokes pass it."""
    count: dict[int, int] = {}
    for passes in solution.ordering.strokes:
        for step in passes:
            count[step.branch] = count.get(step.branch, 0) + 1
    return count


def _nearest_branch(graph, point: np.ndarray, tol: float, eligible=None) -> int | None:
    """The id of the branch passing nearest `point`, if within tol; eligible: None or a
    test a branch must pass to count."""
    return _nearest_branches(graph, np.asarray(point, dtype=float).reshape(1, 2), tol, eligible)[0]


# Candidates per point from the branches' k-d tree: more than any number of branches that
# share one position (a junction's), so the nearest is always among them.
NEAREST_CANDIDATES = 16


def _nearest_branches(graph, points: np.ndarray, tol: float, eligible=None) -> list[int | None]:
    """`_nearest_branch` of each of `points` (E, 2) working px at once (a body of 12,000
    "twice" edits took 5.6 s one edit and one branch at a time): the nearest points found by
    a k-d tree, their distances computed as before (numpy's norm), the first branch in the
    graph's order on a tie."""
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=float).reshape(-1, 2)
    ids = [bid for bid, branch in graph.branches.items() if eligible is None or eligible(branch)]
    if not ids or not len(points):
        return [None] * len(points)
    stacked = np.concatenate([graph.branches[bid].points for bid in ids])
    owner = np.repeat(np.arange(len(ids)), [len(graph.branches[bid].points) for bid in ids])
    finite = np.isfinite(points).all(axis=1)
    index = np.full((len(points), min(NEAREST_CANDIDATES, len(stacked))), len(stacked))
    # a margin past tol: the tree's distances may differ from numpy's in the last bits
    _, index[finite] = cKDTree(stacked).query(points[finite], k=list(range(1, index.shape[1] + 1)),
                                              distance_upper_bound=tol * (1 + 1e-9) + 1e-9)
    found = index < len(stacked)
    safe = np.where(found, index, 0)
    distance = np.linalg.norm(stacked[safe] - points[:, None, :], axis=2)
    distance = np.where(found & (distance <= tol), distance, np.inf)
    best = distance.min(axis=1)
    first = np.where(distance == best[:, None], owner[safe], len(ids)).min(axis=1)
    return [ids[b] if np.isfinite(d) else None for b, d in zip(first.tolist(), best.tolist())]


def _mergeable(graph, branch) -> bool:
    """Whether `branch` joins two different degree-3 nodes (a merge collapses it)."""
    return branch.a != branch.b and graph.degree(branch.a) == 3 and graph.degree(branch.b) == 3
