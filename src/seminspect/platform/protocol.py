"""The robot as a program sees it: a small protocol, in the robot's own (odometry) frame.

A program never touches the simulator. It asks a :class:`Platform` where it believes it is,
tells it where to go, and asks for images, detections and scans. A real robot, or a recorded
log, can stand in for :class:`~seminspect.platform.simulated.SimulatedPlatform` by implementing
the same few methods.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.sensors import Detection, Detector, Frame, LidarScan


@dataclass(frozen=True)
class Motion:
    """Outcome of a motion command, in the robot's frame.

    ``contact`` is where the robot's body touched an obstacle when it was stopped: what a
    bumper, or a legged robot's own obstacle avoidance, reports.
    """

    reached: bool
    blocked: bool
    distance: float
    contact: NDArray[np.float64] | None = None


class Platform(Protocol):
    """What the mission needs of a robot: everything the executive and the run's metrics read."""

    @property
    def time(self) -> float: ...

    @property
    def position(self) -> NDArray[np.float64]: ...

    @property
    def yaw(self) -> float: ...

    @property
    def distance_travelled(self) -> float: ...

    @property
    def camera_pitch(self) -> float:
        """The camera's tilt below the horizon [rad]."""
        ...

    @property
    def frames(self) -> int:
        """Camera frames taken so far."""
        ...

    @property
    def scans(self) -> int:
        """LiDAR scans taken so far."""
        ...

    @property
    def blocked_moves(self) -> int:
        """Motions stopped by an obstacle so far."""
        ...

    @property
    def detector(self) -> Detector:
        """What segments the camera's frames (runs record its ``name``)."""
        ...

    def trajectory_rows(self) -> NDArray[np.float64]:
        """``(n, 9)`` rows: time, position (3), yaw, odometry position (3), odometry yaw."""
        ...

    def move_to(self, point: ArrayLike, yaw: float | None = None) -> Motion: ...

    def turn_to(self, yaw: float) -> Motion: ...

    def wait(self, seconds: float) -> None: ...

    def capture(self, intensity: bool = True) -> Frame:
        """A camera frame; ``intensity=False`` for a caller that reads only depth and labels
        (``Frame.intensity`` then None; a simulator may skip shading it)."""
        ...

    def detect(self, frame: Frame, level: str, labels: Iterable[str]) -> list[Detection]:
        """:attr:`detector`'s detections of ``labels`` (``level``: instance or part)."""
        ...

    def scan(self) -> LidarScan: ...


def heading_to(origin: ArrayLike, point: ArrayLike) -> float:
    """Yaw that faces ``point`` from ``origin``."""
    delta = np.asarray(point, dtype=np.float64)[:2] - np.asarray(origin, dtype=np.float64)[:2]
    return math.atan2(delta[1], delta[0])
