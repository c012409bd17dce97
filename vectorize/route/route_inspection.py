"""One connected drawing, one stroke: route inspection (Chinese postman) on the branch graph.

A single line visits every branch of its ink once, except where the pen went out and back
(a retraced stem, a crossbar drawn out and back, a sharp spike): those branches are drawn
twice. When the graph has more than two odd-degree nodes, no walk uses every branch once;
the cheapest set of branches to draw twice is a minimum-weight matching of the odd nodes
over shortest-path distances (Edmonds and Johnson's route inspection), in which two of them
may be left for the pen to start and end at (`route_matching`: one exact matching decides
both). Every decided junction (a crossing or a touch at
a degree-4 node, or a cluster where three passes cross) is a set of through-paths here: the
walk never turns there, and a retraced path goes through it the way the pairing says unless
turning there saves more than the turn's price (`retrace_paths`).

The walk itself is Fleury's rule (never cross a bridge of what is left while there is
another way) with the smoothest exit first: at a junction the pen goes as straight as the
drawing still allows, and a stub drawn out and back is taken when the pen passes it.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vectorize.axis.graph import MedialGraph
from vectorize.axis.simplify import slots
from vectorize.route.retrace_paths import RetracePaths
from vectorize.route.route_matching import match_odd
from vectorize.route.traversal import Pass


def _back(p: Pass) -> Pass:
    return Pass(p.branch, p.end)


@dataclass(frozen=True)
class Chain:
    """Branches joined through decided junctions: from (u, u_slot) to (v, v_slot).

    u, v: graph nodes where the chain ends (nodes that are not decided); slots index
    `slots(graph, node)`. A chain through decided junctions only has u = v = -1.
    """

    passes: tuple[Pass, ...]
    u: int
    u_slot: int
    v: int
    v_slot: int
    length: float


@dataclass(frozen=True)
class Route:
    """The single stroke: its branch passes in drawing order, whether it is closed, the
    retraced length (px) the matching added and the odd-degree nodes it matched."""

    passes: tuple[Pass, ...]
    closed: bool
    retraced: float
    odd_nodes: int = 0


def _partners(pairings: dict[int, tuple[tuple[int, int], ...]]) -> dict[int, dict[int, int]]:
    result = {}
    for node, pairs in pairings.items():
        result[node] = {}
        for a, b in pairs:
            result[node][a], result[node][b] = b, a
    return result


def chains(graph: MedialGraph, pairings: dict) -> list[Chain]:
    """Cut the graph into chains between undecided nodes (pairings: node -> slot pairs)."""
    partner = _partners(pairings)
    node_slots = {n: slots(graph, n) for n in graph.incident}
    index = {n: {s: i for i, s in enumerate(sl)} for n, sl in node_slots.items()}
    seen_branch: set[int] = set()
    result = []

    def follow(node: int, slot: int) -> tuple[list[Pass], int, int, float]:
        passes, length = [], 0.0
        while True:
            bid, end = node_slots[node][slot]
            seen_branch.add(bid)
            passes.append(Pass(bid, end))
            branch = graph.branches[bid]
            length += branch.length
            far = branch.b if end == "a" else branch.a
            far_slot = index[far][(bid, "b" if end == "a" else "a")]
            if far not in partner:
                return passes, far, far_slot, length
            node, slot = far, partner[far][far_slot]
            if node_slots[node][slot][0] in seen_branch and (node, slot) == start:
                return passes, -1, -1, length  # back where a closed chain began

    done: set[tuple[int, int]] = set()
    for node in sorted(graph.incident):
        if node in partner:
            continue
        for slot in range(len(node_slots[node])):
            if (node, slot) in done:
                continue
            start = (node, slot)
            passes, far, far_slot, length = follow(node, slot)
            done.add((node, slot))
            done.add((far, far_slot))
            result.append(Chain(tuple(passes), node, slot, far, far_slot, length))
    for node in sorted(partner):
        for slot in range(len(node_slots[node])):
            if node_slots[node][slot][0] in seen_branch:
                continue
            start = (node, slot)
            passes, _, _, length = follow(node, slot)
            result.append(Chain(tuple(passes), -1, -1, -1, -1, length))
    return result


def pieces(graph: MedialGraph, pairings: dict) -> int:
    """How many separate lines the graph falls into when decided junctions are through-paths."""
    return PieceCount(graph, pairings)({})


def cuts_off(graph: MedialGraph, node: int, pairs) -> bool:
    """Whether the passes `pairs` (slot pairs) through `node`, with every other junction left
    free to turn, cut a piece off the line: a pass from a free end to a free end (that pass
    would be a whole line), or one that closes a loop meeting nothing else. A single line
    has no such pass unless it is all of the ink."""
    count = PieceCount(graph, {}, (node,))
    return count({node: pairs}) > count({})


class PieceCount:
    """`pieces` for one graph whose `variable` nodes take many pairings in turn (the search in
    `connect_pairings` asks hundreds of times): the graph's pieces with those nodes' branch
    ends all apart are found once; a count then joins each variable node's pairs of ends (all
    its ends when it is undecided), a union per pair.

    A branch end is a vertex of its own where its node's pairing joins it to its partner (the
    pair shares one vertex); the whole node is one vertex where it is undecided. `fixed`:
    pairings of the nodes that are not variable.
    """

    def __init__(self, graph: MedialGraph, fixed: dict, variable=()) -> None:
        self.variable = tuple(variable)
        apart = set(self.variable)
        partner = _partners({n: p for n, p in fixed.items() if n not in apart})
        ids: dict[tuple[int, int], int] = {}

        def vertex(node: int, slot: int) -> int:
            if node in apart:
                key = (node, slot)
            elif node in partner:
                key = (node, min(slot, partner[node][slot]))
            else:
                key = (node, -1)
            return ids.setdefault(key, len(ids))

        rows, cols = [], []
        for node in graph.incident:
            for slot, (bid, end) in enumerate(slots(graph, node)):
                if end == "a":
                    far = graph.branches[bid].b
                    rows.append(vertex(node, slot))
                    cols.append(vertex(far, slots(graph, far).index((bid, "b"))))
        links = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(ids), len(ids)))
        self.count, label = connected_components(links, directed=False) if ids else (0, np.zeros(0, int))
        self.ends = {n: [int(label[ids[n, slot]]) for slot in range(graph.degree(n))] for n in self.variable}

    def __call__(self, choice: dict) -> int:
        """Pieces when each variable node takes choice[node] (slot pairs), or is undecided
        where `choice` leaves it out."""
        parent: dict[int, int] = {}

        def root(x: int) -> int:
            while parent.get(x, x) != x:
                x = parent[x]
            return x

        joined = 0
        for node in self.variable:
            ends = self.ends[node]
            pairs = choice[node] if node in choice else tuple(zip(range(len(ends) - 1), range(1, len(ends))))
            for a, b in pairs:
                ra, rb = root(ends[a]), root(ends[b])
                if ra != rb:
                    parent[ra] = rb
                    joined += 1
        return int(self.count) - joined


class _Multigraph:
    """Chains (and their retraced copies) as edges between undecided nodes."""

    def __init__(self, chain_list: list[Chain]) -> None:
        self.chains = chain_list
        self.edges: list[int] = []  # edge -> chain index
        self.at: dict[int, list[tuple[int, str]]] = {}  # node -> [(edge, end "u"/"v")]
        self.used: list[bool] = []

    def add(self, chain_index: int) -> None:
        edge = len(self.edges)
        self.edges.append(chain_index)
        self.used.append(False)
        c = self.chains[chain_index]
        self.at.setdefault(c.u, []).append((edge, "u"))
        self.at.setdefault(c.v, []).append((edge, "v"))

    def far(self, edge: int, end: str) -> tuple[int, int]:
        c = self.chains[self.edges[edge]]
        return (c.v, c.v_slot) if end == "u" else (c.u, c.u_slot)

    def slot(self, edge: int, end: str) -> int:
        c = self.chains[self.edges[edge]]
        return c.u_slot if end == "u" else c.v_slot

    def free_at(self, node: int) -> list[tuple[int, str]]:
        return [(e, end) for e, end in self.at.get(node, []) if not self.used[e]]

    def reaches(self, start: int, goal: int, skip: int) -> bool:
        """Whether `goal` can be reached from `start` over unused edges other than `skip`."""
        if start == goal:
            return True
        seen, stack = {start}, [start]
        while stack:
            node = stack.pop()
            for e, end in self.at.get(node, []):
                if self.used[e] or e == skip:
                    continue
                nxt = self.far(e, end)[0]
                if nxt == goal:
                    return True
                if nxt not in seen:
                    seen.add(nxt)
                    stack.append(nxt)
        return False


def _fleury(multi: _Multigraph, start: int, bend, arrive) -> list[tuple[int, str]]:
    """An Euler walk from `start`: (edge, end it leaves from) in order; smoothest exit first.

    bend(node, heading, slot): how much leaving `node` by `slot` turns a pen arriving with
    `heading` ((2,) unit vector, None at the start); arrive(edge, end, heading): the node the
    edge leads to and the heading the pen arrives there with.
    """
    walk: list[tuple[int, str]] = []
    node, heading = start, None
    total = len(multi.edges)
    while len(walk) < total:
        options = multi.free_at(node)
        if not options:
            break
        options.sort(key=lambda o: (bend(node, heading, multi.slot(*o)), o[0]))
        choice = options[0]
        if len(options) > 1:
            for e, end in options:
                far = multi.far(e, end)[0]
                # Not a bridge: the far node is reachable without it, or it is the last way on.
                if far == node or multi.reaches(node, far, e):
                    choice = (e, end)
                    break
        e, end = choice
        multi.used[e] = True
        walk.append(choice)
        node, heading = arrive(e, end, heading)
    return walk


def _first_steps(pred: np.ndarray, sources: np.ndarray) -> np.ndarray:
    """(S, N): the node after source s on its shortest path to each node (the node itself
    where it is the source's neighbour, the source, or unreachable), from dijkstra's (S, N)
    predecessors, by pointer doubling."""
    own = np.arange(pred.shape[1])
    step = np.where((pred == sources[:, None]) | (pred < 0), own, pred)
    while True:
        further = np.take_along_axis(step, step, axis=1)
        if np.array_equal(further, step):
            return step
        step = further


def plan_routes(graph: MedialGraph, pairings: dict, *, stroke_width: float, directions: dict,
                end_cost: dict[int, float] | None = None, weight: dict[int, float] | None = None,
                turn_price: dict | None = None) -> list[Route]:
    """One stroke per piece of the graph over all its branches, retracing as little as it can.

    pairings: node -> slot pairs of its through-paths (decided junctions); directions: node
    -> (D, 2) unit tangents per slot, leaving the node (for junctions of degree >= 3);
    end_cost: px added when the pen starts or ends at a node (default 0): makes some nodes,
    such as the tip of a sharp corner's spur, poor places to start. weight: branch id ->
    factor on its length when retraces are chosen (default 1; a user's "draw this twice"
    makes it small, "once" large). turn_price: decided node -> {(slot, slot): px} where a
    retraced path may turn there and what that costs (`retrace_paths.turn_prices`; default:
    nowhere). A graph that is one piece under the pairings (see `connect_pairings`) gives
    exactly one route.
    """
    chain_list = chains(graph, pairings)
    nodes = sorted({c.u for c in chain_list if c.u >= 0} | {c.v for c in chain_list if c.v >= 0})
    where = {n: i for i, n in enumerate(nodes)}
    open_chains = [c for c in chain_list if c.u >= 0]
    links = coo_matrix((np.ones(len(open_chains)), ([where[c.u] for c in open_chains], [where[c.v] for c in open_chains])),
                       shape=(len(nodes), len(nodes)))
    _, label = connected_components(links, directed=False)
    groups: dict[int, list[Chain]] = {}
    for c in open_chains:
        groups.setdefault(int(label[where[c.u]]), []).append(c)
    partner = _partners(pairings)
    routes = [_route(graph, group, stroke_width, directions, end_cost or {}, weight or {}, partner, turn_price or {})
              for _, group in sorted(groups.items())]
    routes += [Route(c.passes, True, 0.0) for c in chain_list if c.u < 0]
    return routes


def _route(graph: MedialGraph, chain_list: list[Chain], stroke_width: float, directions: dict,
           end_cost: dict[int, float], weight: dict[int, float], partner: dict[int, dict[int, int]],
           turn_price: dict) -> Route:
    """The route over one connected piece of chains (none of them closed on its own);
    partner: decided node -> {slot: partner slot}; turn_price: `retrace_paths.turn_prices`."""
    nodes = sorted({c.u for c in chain_list if c.u >= 0} | {c.v for c in chain_list if c.v >= 0})
    where = {n: i for i, n in enumerate(nodes)}
    degree = np.zeros(len(nodes), dtype=int)
    for c in chain_list:
        if c.u >= 0:
            degree[where[c.u]] += 1
            degree[where[c.v]] += 1

    def turn(node: int, entry: int | None, out: int) -> float:
        """Bending of a pass into the node by slot `entry` and out by `out`: 0 straight, 2 back."""
        if entry is None or node not in directions:
            return 0.0
        d = directions[node]
        return 1.0 + float(np.dot(d[entry], d[out]))

    def leave_penalty(node: int, slot: int) -> float:
        # Tie-break by smoothness: at a three-way junction, retracing one branch leaves the
        # other two to be walked through; prefer the retrace that leaves them straightest.
        if node not in directions or len(directions[node]) != 3:
            return 0.0
        a, b = (i for i in range(3) if i != slot)
        return 0.25 * stroke_width * turn(node, a, b)

    odd = [nodes[i] for i in range(len(nodes)) if degree[i] % 2]
    pairs_out: list[tuple[int, int]] = []
    ends: list[int] = []
    chain_list = list(chain_list)
    retraced = 0.0
    if odd:
        # What retracing each branch costs: its length, with the branch's weight.
        cost_of = {p.branch: graph.branches[p.branch].length * weight.get(p.branch, 1.0)
                   for c in chain_list for p in c.passes}
        paths = RetracePaths(graph, partner, cost_of, odd, directions, stroke_width, turn_price)
        # The path from odd[i] to odd[j] leaves and reaches them by the slots its first and last
        # steps say (from the predecessors, without walking it).
        first = _first_steps(paths.pred, np.array(paths.sources))
        m = len(odd)
        cost = np.full((m, m), np.inf)
        for i in range(m):
            for j in range(i + 1, m):
                dij = paths.dist[i, paths.sources[j]]
                if np.isfinite(dij):
                    out, into = paths.first_slots(first, i, j)
                    dij += leave_penalty(odd[i], out) + leave_penalty(odd[j], into)
                cost[i, j] = cost[j, i] = dij
        ends_cost = np.array([end_cost.get(n, 0.0) for n in odd])
        pairs_out, ends = match_odd(cost, ends_cost)
        for i, j in pairs_out:
            for passes, (u, u_slot), (v, v_slot) in paths.legs(i, j):
                length = sum(graph.branches[p.branch].length for p in passes)
                chain_list.append(Chain(passes, u, u_slot, v, v_slot, length))
                retraced += length
    multi = _Multigraph(chain_list)
    for k, c in enumerate(chain_list):
        if c.u >= 0:
            multi.add(k)
    if ends:
        # Start at the free end if one of the two is one: the walk then reaches every
        # junction along a branch and can go on as straight as the drawing allows.
        start = min((odd[i] for i in ends), key=lambda n: (len(multi.at[n]), n))
    else:
        # A closed walk: begin at the top-left node (any node would do).
        start = min(nodes, key=lambda n: (float(graph.positions[n].sum()), n))

    def walked(e: int, end: str) -> tuple[Pass, ...]:
        chain = chain_list[multi.edges[e]]
        return chain.passes if end == "u" else tuple(_back(p) for p in reversed(chain.passes))

    bands = shared_bands(graph, [p for c in chain_list for p in c.passes], stroke_width)

    def bend(node: int, heading, out: int) -> float:
        """Bending of a pen arriving with `heading` and leaving by slot `out`: 0 straight, 2 back."""
        if heading is None or node not in directions:
            return 0.0
        return 1.0 - float(np.dot(heading, directions[node][out]))

    def arrive(e: int, end: str, heading):
        far, far_slot = multi.far(e, end)
        seq = walked(e, end)
        last = seq[-1]
        if last.branch not in bands:
            return far, (-directions[far][far_slot] if far in directions else None)
        # A short band drawn twice carries the ink of two passes: its axis runs between
        # their headings, and each pass keeps the heading it had where it entered the band.
        if len(seq) == 1:
            return far, heading
        into = graph.branches[last.branch].node(last.start)
        if into not in directions:
            return far, None
        before = slots(graph, into).index((seq[-2].branch, seq[-2].end))
        return far, -directions[into][before]

    walk = _fleury(multi, start, bend, arrive)
    passes: list[Pass] = []
    for e, end in walk:
        passes.extend(walked(e, end))
    return Route(tuple(passes), not ends, retraced, len(odd))


# Stroke widths: two passes at an angle a share ink over about w / sin(a / 2), 6 widths at
# a = 19 degrees; passes closer to parallel than that head along the band's own axis anyway.
# The bands at the base of the cursive h's measured 4.1 widths (handy_lady_tidy_attic-0-11,
# mail_the_ticket_at_ten-0-7); an l's stem drawn down and back up between two junctions,
# 11 widths, is left to its axis.
BAND_MAX_WIDTHS = 6.0


def shared_bands(graph: MedialGraph, passes, stroke_width: float, *,
                 max_widths: float = BAND_MAX_WIDTHS) -> set[int]:
    """Branches between two junctions, at most `max_widths` stroke widths long, that the
    route walks twice (passes: every pass of the route): bands of ink two passes share, such
    as the base of a cursive h or l, where the way in and the stem drawn back up run
    together between the crossing and the loop."""
    count: dict[int, int] = {}
    for p in passes:
        count[p.branch] = count.get(p.branch, 0) + 1
    result = set()
    for bid, k in count.items():
        branch = graph.branches[bid]
        if (k >= 2 and branch.a != branch.b and branch.length <= max_widths * stroke_width
                and graph.degree(branch.a) >= 3 and graph.degree(branch.b) >= 3):
            result.add(bid)
    return result


def connect_pairings(graph: MedialGraph, ranked: dict, costs: dict, *, fixed: dict | None = None,
                     evidence: dict | None = None, max_tries: int = 400) -> tuple[dict, int]:
    """Pairings for the decided junctions under which the drawing stays one piece.

    ranked[node]: its pairings, preferred first; costs[node]: the cost of each. A pairing
    that turns a touch into a crossing (or back) can cut the line into separate loops; the
    search tries assignments best-first by total cost until the graph is one piece. If none
    within `max_tries` is, junctions are left undecided, least sure first, until it is:
    there the walk may turn any way. Returns node -> pairing (undecided nodes left out) and
    the number of assignments tried. fixed: node -> slot pairs decided elsewhere (three
    passes through a point), part of every assignment and never changed. evidence[node]:
    the costs of its pairings with the verdict uncapped; of assignments of equal cost, the
    one that changes the less sure verdicts wins.
    """
    nodes = sorted(ranked)
    fixed = fixed or {}

    def assign(ranks: tuple[int, ...]) -> dict:
        return {**fixed, **{n: ranked[n][r] for n, r in zip(nodes, ranks)}}

    # Ties of cost (junctions read as sure as `costs` allows) go by the evidence uncapped;
    # a node whose pairings were cut down since (a user's pairing edit) by its costs.
    evidence = evidence or {}
    fine = {n: evidence[n] if len(evidence.get(n, ())) == len(costs[n]) else costs[n] for n in nodes}
    start = tuple(0 for _ in nodes)
    pieces = PieceCount(graph, fixed, nodes)  # counts under the ranked nodes' pairings (fixed ones stay)
    best_key, best_ranks = (pieces(assign(start)), 0.0, 0.0), start
    tried = 1
    heap = [(0.0, 0.0, start, 0)]
    seen = {start}
    while best_key[0] > 1 and heap and tried < max_tries:
        cost, weight, ranks, last = heapq.heappop(heap)
        if ranks != start:
            key = (pieces(assign(ranks)), cost, weight)
            tried += 1
            if key < best_key:
                best_key, best_ranks = key, ranks
                if key[0] == 1:
                    break
        # Children change one decision at or after the last changed one: each assignment
        # is generated once, in order of increasing total cost.
        for j in range(last, len(nodes)):
            if ranks[j] + 1 < len(ranked[nodes[j]]):
                child = ranks[:j] + (ranks[j] + 1,) + ranks[j + 1:]
                if child not in seen:
                    seen.add(child)
                    delta = costs[nodes[j]][ranks[j] + 1] - costs[nodes[j]][ranks[j]]
                    fine_delta = fine[nodes[j]][ranks[j] + 1] - fine[nodes[j]][ranks[j]]
                    heapq.heappush(heap, (cost + delta, weight + fine_delta, child, j))
    pairing = assign(best_ranks)
    count = best_key[0]
    for n in fixed:
        del pairing[n]
    if count > 1:
        # Least sure first: the node whose second choice costs least.
        # A pairing the user fixed (its only choice) stays, even if the line then falls apart.
        for node in sorted((n for n in nodes if len(ranked[n]) > 1), key=lambda n: (costs[n][1], n)):
            trial = {n: p for n, p in pairing.items() if n != node}
            now = pieces({**fixed, **trial})
            if now < count:
                pairing, count = trial, now
            if count <= 1:
                break
    return pairing, tried
