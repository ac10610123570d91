"""The observation ``z_k`` of 000 Sec III: the one input of every layer's registration R."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import IDENTITY_QUAT, Quat, Vec3, as_point, as_quaternion


@dataclass(frozen=True, slots=True)
class Observation:
    """``z_k = (z^p, z^q, z^l, z^s, z^a, z^i)``: position, orientation, label, score, area, image.

    A detection (target or feature) fills every field. A view pose registered by the planner
    (Level and Pose layers) carries the robot's pose and image with an empty label.

    Attributes:
        position: ``z^p``, metres in the world frame.
        orientation: ``z^q``, unit quaternion ``[x, y, z, w]`` (the camera's, for detections).
        label: ``z^l``, semantic class (``car``) or part (``front-left-door``).
        score: ``z^s``, segmentation confidence in ``[0, 1]``.
        mask_area: ``z^a``, segmented mask area in pixels.
        image: ``z^i``, a reference to the RGB image (a path or frame id), never pixels.
        stamp: time of the observation in seconds.
    """

    position: Vec3
    orientation: Quat = field(default_factory=IDENTITY_QUAT.copy)
    label: str = ""
    score: float = 1.0
    mask_area: float = 0.0
    image: str | None = None
    stamp: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", as_point(self.position, "observation position"))
        object.__setattr__(
            self, "orientation", as_quaternion(self.orientation, "observation orientation")
        )
        if not isinstance(self.label, str):
            raise InvalidInputError(f"observation label must be text, got {self.label!r}")
        if not (math.isfinite(self.score) and 0.0 <= self.score <= 1.0):
            raise InvalidInputError(f"observation score must lie in [0, 1], got {self.score}")
        if not (math.isfinite(self.mask_area) and self.mask_area >= 0.0):
            raise InvalidInputError(f"observation mask area must be >= 0, got {self.mask_area}")
        if not math.isfinite(self.stamp):
            raise InvalidInputError(f"observation stamp must be finite, got {self.stamp}")

    @classmethod
    def view_pose(
        cls,
        position: ArrayLike,
        orientation: ArrayLike = IDENTITY_QUAT,
        image: str | None = None,
        stamp: float = 0.0,
    ) -> Observation:
        """A planner-provided view pose (Level and Pose layers): no label, full confidence."""
        return cls(np.asarray(position), np.asarray(orientation), image=image, stamp=stamp)
