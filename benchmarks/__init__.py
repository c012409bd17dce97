"""Benchmarks of onestroke: the runnable scripts at this level print figures (medians); the
packages hold what they share.

- `benchmarks.sets`: the drawing sets and rendering conditions (each with its ground truth),
  and the other inputs the benchmarks and tests feed in (embroidery designs, laser jobs,
  batch folders, fuzzed command lines);
- `benchmarks.metrics`: what is measured on an output (the paper's Table 1, ink, route,
  satin columns, stitch checks, an independent GRBL simulation) and the result tables;
- `benchmarks.common`: rendering, processes and installs, running another checkout's code.

Run a script from the repository root as a module: `python -m benchmarks.vectorize_bench`.
The tests import the packages the same way (`from benchmarks.sets.hershey import hershey_set`).
"""
