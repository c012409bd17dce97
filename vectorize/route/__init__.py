"""Stage 4, graph traversal (paper 3.3.2): the classified graph walked into ordered passes.

In: the simplified graph of `vectorize.axis` and the junction pairings of
`vectorize.junctions`. Out: the drawing order as polylines (`traversal.Ordering`: passes of
branches, px), found by the rules per node degree with flip-and-retry (`traversal`), or for
one connected line by route inspection (`route_inspection`, `route_matching`: which branches
are drawn twice; `route_ends`: where the pen may start and end).
"""
