"""Stage 2, the medial axis and its simplification (paper 3.2).

In: the outline rings and gray image of `vectorize.raster`. Out: a `graph.MedialGraph` (nodes
joined by branches: polylines with radii, px) from the Voronoi diagram (`voronoi`,
`medial_axis`), pruned of noise branches (`pruning`), with pen gaps bridged (`gaps`), then
simplified (`simplify`: degree-3 pairs merged into degree-4 crossings, Y-junctions kept;
`clusters`: three passes through one point read as one node) into a `simplify.Simplified`.
"""
