"""Training of the intersection CNN: synthetic data, model, train command, ONNX export.

Only `model` and `train` import torch (the `train` extra); `synth` and `validate` need
numpy/scipy/onnxruntime only, and nothing outside this package imports torch.
"""
