"""Stage 5, curve fitting (paper 3.4): ordered polylines to cubic Bézier strokes.

In: the traced points of `vectorize.route` with the medial axis's radii. Out: `Stroke`s
(control points (K, 4, 2) px) fitted with scipy's splines after filtering uncertain points
(`fitting`), kept inside the ink (`ink_guard`), one curve for both passes of a retraced
stretch (`retraces`), and the ink width along each stroke (`ink_width`).
"""
