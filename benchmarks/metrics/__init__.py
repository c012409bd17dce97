"""What the benchmarks measure on an output against its ground truth: the paper's Table 1
metrics (`table1`), ink fidelity (`ink`), route figures, satin and zigzag columns
(`columns`), stitch-plan checks (`stitches`), an independent GRBL simulation (`grbl_sim`),
and the benchmark's tables (`tables`)."""
