"""Benchmarks of onestroke: the runnable scripts at this level print figures (medians); the
packages hold what they share.

- `benchmarks.sets`: the drawing sets and rendering conditions (each with its ground truth),
  and the other inputs the benchmarks and tests feed in (embroidery designs, laser jobs,
  batch folders, fuzzed command lines);
- `benchmarks.metrics`: what is measured on an output (the paper's Table 1, ink, route,
  satin columns, stitch checks, an independent GRBL simulation) and the result tables;
- `benchmarks.common`: rendering, processes and installs, running another checkout's code.

Run a script from the repository root as a module, `python -m benchmarks.vectorize_bench`, or
as a file from anywhere, `python benchmarks/vectorize_bench.py`. As a file the script's own
folder heads the import path; each script's first lines put the repository root in its place,
as `-m` from the root has it, so that `benchmarks` imports (a child that another checkout's
code runs, `common.checkout.rerun_on`, starts with -P and keeps its path). The tests import
the packages as modules (`from benchmarks.sets.hershey import hershey_set`).
"""
