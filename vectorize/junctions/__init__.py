"""Stage 3, intersection classification (paper 3.3.1): how the pen went through each junction.

In: the simplified graph of `vectorize.axis` and the gray image. Out: per degree-4 node a
`intersections.JunctionVerdict` (crossing or touching, with a confidence) from the image
crops (`junction_crop`, `crossing_point`) and the shipped CNN (`cnn_classifier`) or the
geometric rule (`classifiers` picks by name); per triple point a pairing of its six feet
(`pass_crop`, `pass_scorer`).
"""
