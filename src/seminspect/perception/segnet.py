"""The learned detector's network: a compact U-Net of depthwise-separable convolutions, from
scratch (no pretrained weights), in torch (the ``rl`` extra; never imported at run time, where
:mod:`.learned` runs its ONNX export).

Input: RGB in [0, 1], ``(N, 3, H, W)``; any size works (the decoder upsamples to each skip's
size), and the export fixes one. Three heads at full resolution, all logits:

- ``classes``: one per target class of :data:`.shards.CLASSES` (background, car, truck,
  building);
- ``parts``: one per part name of the dataset (``none`` first), trained on target pixels only;
- ``edges``: one, the seams where two instances touch, so that two cars parked side by side
  come out as two connected components rather than one.

Why this shape: the detector runs on the robot's CPU beside everything else, so the network
is small (0.33 M parameters with 21 parts, 1.3 MB in ONNX) and depthwise-separable; the masks
must follow object outlines, so the decoder has skips from every encoder stage.
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F  # noqa: N812 - torch's own convention
from torch import Tensor, nn

from seminspect.core.errors import InvalidInputError

#: Channels of the encoder's stages: full resolution, then /2, /4, /8, /16.
DEFAULT_CHANNELS = (24, 48, 96, 160, 256)


@dataclass(frozen=True)
class SegNetConfig:
    """What fixes a network: its label vocabularies, the image size it is trained and
    exported at ``(H, W)``, and its stage widths."""

    classes: tuple[str, ...]
    parts: tuple[str, ...]
    input_size: tuple[int, int]
    channels: tuple[int, ...] = DEFAULT_CHANNELS

    def __post_init__(self) -> None:
        if len(self.classes) < 2 or len(self.parts) < 1:
            raise InvalidInputError("a network needs background and a class, and a part 'none'")
        if len(self.channels) < 2 or min(self.channels) < 4:
            raise InvalidInputError(f"stage widths must be >= 4, at least two: {self.channels}")
        if min(self.input_size) < 8:
            raise InvalidInputError(f"input size {self.input_size} is smaller than 8 pixels")

    def to_dict(self) -> dict[str, list[str] | list[int]]:
        return {k: list(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict[str, list]) -> SegNetConfig:
        return cls(**{k: tuple(v) for k, v in data.items()})


class SeparableConv(nn.Sequential):
    """3 x 3 depthwise then 1 x 1 pointwise convolution, each with batch norm; ReLU after."""

    def __init__(self, cin: int, cout: int, stride: int = 1):
        super().__init__(
            nn.Conv2d(cin, cin, 3, stride, 1, groups=cin, bias=False),
            nn.BatchNorm2d(cin),
            nn.ReLU(inplace=True),
            nn.Conv2d(cin, cout, 1, bias=False),
            nn.BatchNorm2d(cout),
            nn.ReLU(inplace=True),
        )


class SegNet(nn.Module):
    """The encoder-decoder of the module docstring; :meth:`forward` gives the three heads'
    logits ``(classes, parts, edges)``, each ``(N, C, H, W)``."""

    def __init__(self, config: SegNetConfig):
        super().__init__()
        self.config = config
        widths = config.channels
        self.stem = nn.Sequential(
            nn.Conv2d(3, widths[0], 3, 1, 1, bias=False),
            nn.BatchNorm2d(widths[0]),
            nn.ReLU(inplace=True),
            SeparableConv(widths[0], widths[0]),
        )
        self.down = nn.ModuleList(
            nn.Sequential(SeparableConv(cin, cout, 2), SeparableConv(cout, cout))
            for cin, cout in itertools.pairwise(widths)
        )
        self.up = nn.ModuleList(
            nn.Sequential(SeparableConv(deep + skip, skip), SeparableConv(skip, skip))
            for deep, skip in zip(widths[:0:-1], widths[-2::-1], strict=True)
        )
        self.heads = nn.Conv2d(widths[0], len(config.classes) + len(config.parts) + 1, 1)

    def forward(self, images: Tensor) -> tuple[Tensor, Tensor, Tensor]:
        features = [self.stem(images - 0.5)]  # centred: the inputs are in [0, 1]
        for stage in self.down:
            features.append(stage(features[-1]))
        x = features.pop()
        for stage in self.up:
            skip = features.pop()
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = stage(torch.cat([x, skip], dim=1))
        out = self.heads(x)
        classes, parts = len(self.config.classes), len(self.config.parts)
        return out[:, :classes], out[:, classes : classes + parts], out[:, classes + parts :]


class Probabilities(nn.Module):
    """The network as it is exported: softmax over classes and parts, sigmoid of the seams."""

    def __init__(self, net: SegNet):
        super().__init__()
        self.net = net

    def forward(self, images: Tensor) -> tuple[Tensor, Tensor, Tensor]:
        classes, parts, edges = self.net(images)
        return classes.softmax(1), parts.softmax(1), torch.sigmoid(edges)


def parameter_count(net: nn.Module) -> int:
    return sum(p.numel() for p in net.parameters())
