"""The seam between a camera frame and what a mission sees in it: the :class:`Detector`.

A detector segments a frame into objects (``level="instance"``, by class) or their parts
(``level="part"``, by part name), as 000 Sec III's YOLO and CLIPSeg do. The platform takes any
detector; :class:`TruthDetector`, the default, reads the simulator's per-pixel labels and puts
them through the fault model of :class:`~seminspect.sensors.noise.NoiseModel`
(:func:`~seminspect.sensors.segmentation.detect`). A detector that reads pixels uses the
frame's image, depth and camera model only, and says so with a true ``reads_image``
(:func:`reads_image`): a platform then renders the image of every frame, including those a
program asks for without it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np

from seminspect.sensors.camera import Frame
from seminspect.sensors.noise import NoiseModel
from seminspect.sensors.segmentation import Detection, Level, detect
from seminspect.worlds import World


class Detector(Protocol):
    """Objects or parts in a camera frame, with label, mask, score and level."""

    @property
    def name(self) -> str:
        """What runs record as the detector that made their detections."""
        ...

    def detect(self, frame: Frame, level: Level, labels: Sequence[str]) -> list[Detection]:
        """The detections of ``labels`` (classes for objects, part names for parts)."""
        ...


def reads_image(detector: Detector) -> bool:
    """Whether ``detector`` reads the frame's image (a model does; the simulator's labels do
    not): an optional ``reads_image`` attribute, False when absent, so that any detector
    without it keeps the cheaper frames."""
    return bool(getattr(detector, "reads_image", False))


@dataclass(eq=False)
class TruthDetector:
    """The simulator's own labels with the fault model's erosion, bleed, misses, score noise
    and false positives, drawn from ``rng``."""

    world: World
    noise: NoiseModel
    rng: np.random.Generator
    name: ClassVar[str] = "truth"

    def detect(self, frame: Frame, level: Level, labels: Sequence[str]) -> list[Detection]:
        wanted = tuple(labels)
        by_label = {"classes": wanted} if level == "instance" else {"parts": wanted}
        return detect(frame, self.world, level, noise=self.noise, rng=self.rng, **by_label)
