"""A fake :class:`~seminspect.platform.simulated.Platform` and a mission context around it.

The fake robot teleports (a move takes its distance at 1 m/s), sees nothing but a scripted
intensity image, and reports the detections a test hands it. The phase tests of
``tests/missions/xflie`` drive one phase at a time on it, without the simulator.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.geometry.transforms import quat_from_yaw, wrap_angle
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import FREE, VoxelMap
from seminspect.missions.xflie.approach import local_planner
from seminspect.missions.xflie.config import ResolvedMissionConfig, make_config, resolve
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.metrics import CoverageRecorder
from seminspect.missions.xflie.navigation import Navigator
from seminspect.missions.xflie.recorder import MissionRecorder
from seminspect.platform.protocol import Motion
from seminspect.sensors import CameraModel, Detection, Frame, LidarScan

#: A small camera keeps the fake's frames cheap (and large enough for ORB features).
CAMERA = CameraModel(width=320, height=240, hfov_deg=69.4, max_range=10.0)


class FakePlatform:
    """Teleports, takes blank frames and reports scripted detections."""

    def __init__(self, position: ArrayLike = (0.0, 0.0, 0.7), yaw: float = 0.0) -> None:
        self._position = np.asarray(position, dtype=np.float64)
        self._yaw = yaw
        self._time = 0.0
        self.camera_pitch = 0.0
        self.distance_travelled = 0.0
        self.frames = 0
        self.scans = 0
        self.blocked_moves = 0
        #: Every heading the robot turned to, in order.
        self.headings: list[float] = []
        #: What the camera shows from a pose: ``image(position, yaw) -> (H, W) uint8``.
        self.image: Callable[[NDArray[np.float64], float], NDArray[np.uint8]] = _blank
        #: The detections of a frame: ``detections(frame, level, labels) -> list``.
        self.detections: Callable[[Frame, str, tuple[str, ...]], list[Detection]] = (
            lambda frame, level, labels: []
        )
        #: Points the LiDAR returns (in the odometry frame).
        self.scan_points = np.empty((0, 3))

    @property
    def time(self) -> float:
        return self._time

    @property
    def position(self) -> NDArray[np.float64]:
        return self._position.copy()

    @property
    def yaw(self) -> float:
        return self._yaw

    def trajectory_rows(self) -> NDArray[np.float64]:
        return np.empty((0, 9))

    def move_to(self, point: ArrayLike, yaw: float | None = None) -> Motion:
        goal = np.asarray(point, dtype=np.float64)
        distance = float(np.linalg.norm(goal - self._position))
        self._time += distance
        self.distance_travelled += distance
        self._position = goal
        if yaw is not None:
            self._yaw = wrap_angle(yaw)
            self.headings.append(self._yaw)
        return Motion(True, False, distance)

    def turn_to(self, yaw: float) -> Motion:
        return self.move_to(self._position, yaw)

    def wait(self, seconds: float) -> None:
        self._time += seconds

    def capture(self, intensity: bool = True) -> Frame:
        self.frames += 1
        self._time += 0.3
        shape = (CAMERA.height, CAMERA.width)
        quat = quat_from_yaw(self._yaw)
        return Frame(
            depth=np.full(shape, np.inf, np.float32),
            instance=np.zeros(shape, np.int32),
            class_id=np.zeros(shape, np.int16),
            part_id=np.zeros(shape, np.int16),
            intensity=self.image(self._position, self._yaw) if intensity else None,
            face=np.full(shape, -1, np.int32),
            position=self._position.copy(),
            orientation=quat,
            stamp=self._time,
            camera=CAMERA,
        )

    def detect(self, frame: Frame, level: str, labels: Iterable[str]) -> list[Detection]:
        return self.detections(frame, level, tuple(labels))

    def scan(self) -> LidarScan:
        self.scans += 1
        count = len(self.scan_points)
        return LidarScan(
            points=self.scan_points.copy(),
            instance=np.zeros(count, np.int32),
            class_id=np.zeros(count, np.int16),
            part_id=np.zeros(count, np.int16),
            ring=np.zeros(count, np.int16),
            origin=self._position.copy(),
            stamp=self._time,
        )


def car_in_view(platform: FakePlatform, distance: float = 4.0) -> None:
    """The fake camera sees a flat car-sized patch ``distance`` ahead, and detects it."""
    mask = np.zeros((CAMERA.height, CAMERA.width), bool)
    mask[100:160, 120:200] = True

    def capture_with_depth(intensity: bool = True, original=platform.capture):
        frame = original(intensity=intensity)
        frame.depth[mask] = distance
        return frame

    platform.capture = capture_with_depth
    box = (120, 100, 200, 160)
    platform.detections = lambda frame, level, labels: (
        [Detection("car", mask, int(mask.sum()), 0.9, box, 1, "instance", distance)]
        if level == "instance" and "car" in labels
        else []
    )


def _blank(position: NDArray[np.float64], yaw: float) -> NDArray[np.uint8]:
    return np.zeros((CAMERA.height, CAMERA.width), np.uint8)


class EventList:
    """An event sink that keeps events in memory."""

    def __init__(self) -> None:
        self.events: list[dict[str, Any]] = []

    def log_event(self, kind: str, sim_time: float, **fields: Any) -> None:
        self.events.append({"t": sim_time, "event": kind, **fields})

    def kinds(self) -> list[str]:
        return [e["event"] for e in self.events]


def fake_context(
    platform: FakePlatform | None = None,
    *,
    settings: dict[str, Any] | None = None,
    size: float = 20.0,
    height: float = 3.0,
    known_free: bool = True,
) -> tuple[MissionContext, EventList]:
    """A context on a fake platform in a ``size`` x ``size`` x ``height`` m map (free, or
    unknown)."""
    platform = platform or FakePlatform()
    config: ResolvedMissionConfig = resolve(
        make_config({"world": "campus", "time_budget_s": 600.0} | (settings or {}))
    )
    half = size / 2
    occupancy = VoxelMap.empty([-half, -half, -0.25], [half, half, height - 0.25], 0.5)
    if known_free:
        occupancy.states[:] = FREE
    graph = LayeredSemanticGraph(config.params, robot_position=platform.position)
    events = EventList()
    recorder = MissionRecorder(
        lambda: platform.time, CoverageRecorder(config.inspection.d_view), events
    )
    navigator = Navigator(
        platform,
        occupancy,
        local_planner(config),
        lambda frame: None,
        lidar_every_m=2.0,
        camera_every_m=4.0,
        clear_misses_to=5.0,
        timers=recorder.timers,
        guard_unknown=config.mode == "aerial",
    )
    ctx = MissionContext(
        config, platform, occupancy, graph, navigator, recorder, None, min_height=0.15
    )
    return ctx, events


def headings_apart(headings: list[float]) -> list[float]:
    """Angles turned between consecutive headings [rad]."""
    return [abs(math.remainder(b - a, math.tau)) for a, b in itertools.pairwise(headings)]
