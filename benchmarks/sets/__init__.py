"""The benchmarks' inputs: one module per drawing set and rendering condition, each drawing
with its ground truth (`benchmarks.metrics.ground_truth.GroundTruth`), and the other inputs
the benchmarks and tests share. `registry` names the vectorizer benchmark's sets."""
