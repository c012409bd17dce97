"""The crossing-vs-touching network: a small CNN (about 63k parameters).

Input (N, 2, S, S) float: the near and far junction crops of `vectorize.junctions.junction_crop`.
Output (N,) probability that the two strokes cross. Needs PyTorch (the `train` extra);
inference uses the exported ONNX file through onnxruntime only.
"""

from __future__ import annotations

import torch
from torch import nn


def _block(cin: int, cout: int, *, stride: int = 1, pool: bool = True) -> list[nn.Module]:
    layers: list[nn.Module] = [
        nn.Conv2d(cin, cout, 3, stride=stride, padding=1, bias=False),
        nn.BatchNorm2d(cout),
        nn.ReLU(inplace=True),
    ]
    return layers + [nn.MaxPool2d(2)] if pool else layers


class CrossingNet(nn.Module):
    """A stride-2 stem (48 -> 24 px), three conv + pool blocks (-> 3 px), global average
    pooling, one logit. Small on purpose: 8 augmented copies of every junction of a
    drawing run on a CPU in a few milliseconds.

    The pass scorer of triple points is the same design on its 4-channel 32 px crops
    (`vectorize.junctions.pass_crop`): `pass_net()`."""

    def __init__(self, channels: tuple[int, ...] = (24, 32, 64, 64), inputs: int = 2) -> None:
        super().__init__()
        layers = _block(inputs, channels[0], stride=2, pool=False)
        for cin, cout in zip(channels[:-1], channels[1:]):
            layers += _block(cin, cout)
        self.features = nn.Sequential(*layers)
        self.head = nn.Linear(channels[-1], 1)

    def forward(self, crops: torch.Tensor) -> torch.Tensor:
        """Logits (N,) of "crossing"."""
        x = self.features(crops)
        return self.head(x.mean(dim=(2, 3))).squeeze(1)


def pass_net() -> CrossingNet:
    """The pass scorer (about 24k parameters): does the candidate pass drawn in the crop go
    straight through the ink of a triple point? (N, 4, 32, 32) -> logits (N,)."""
    return CrossingNet(channels=(12, 24, 32, 48), inputs=4)


class Probability(nn.Module):
    """The network with a sigmoid on top: what the ONNX file computes."""

    def __init__(self, net: CrossingNet) -> None:
        super().__init__()
        self.net = net

    def forward(self, crops: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.net(crops))

