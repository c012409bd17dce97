"""What one studio request may cost: budgets checked before the heavy work.

The studio answers while someone waits at the page (issue 25: no request takes the server
over 2 s or 500 MB, but a real job that is sent). Option ranges (`onestroke.ranges`) bound
what a setting may be; a few settings inside their ranges still make work that grows with
the input, and the studio refuses those before doing it (400, one line: what was found, the
budget, what to change). The command line and batch set no budget and take the time.
Figures: docs/studio.md, "The heaviest requests" (`python benchmarks/studio_worst.py`).
"""

# Odd-degree nodes route inspection pairs in single-line mode (`VectorizeOptions.max_odd_nodes`).
# Its exact matching (networkx's blossom, pure Python) grows as their cube: on word-like graphs
# 102 / 148 / 198 odd nodes took 0.42 / 0.92 / 2.37 s of CPU (benchmarks/route_matching_speed.py,
# load 6); loops.png at threshold 0.05 has 454 (about 21 s). The longest lines of the cursive set
# (39 letters) have 96, the other benchmark sets at most 18.
ODD_NODES = 120
# The same in multi-stroke mode, where each pair of them is a stroke to order and fit (about
# 6 ms of CPU each, linear): loops.png at threshold 0.08 has 266 (1.6 s), at 0.05 380 (2.5 s).
MULTI_ODD_NODES = 200

# Steps along the curve of an embroidery preview or download (`EmbroideryJob.max_steps`):
# rows of a satin or zigzag, arrows, or stitches of a running or triple line (curve length
# over spacing or stitch length). Satin costs the most per step, about 45 us (131,032
# stitches in 52,490 steps: 2.4 s of CPU at load 6); loops.png on a 1,500 mm hoop at satin's
# default 0.4 mm spacing is 13,000 steps.
STEPS = 20_000
