"""Manual refinement (paper 4.3): a user's edits applied at the stages' boundaries.

In: an `edits.Edits` (settings, and corrections by position: splits, merges, pairings,
passes, starts, reversals, retraces, unbridged gaps; plain data that survives a file) and
a `refine.StageCache` of earlier results. Out: the same pipeline's `Drawing`, re-running
only the stages after the earliest edit (`refine`); the choices a user has at a triple
point (`pass_choices`). Imported only by the studio and `--edits`.
"""
