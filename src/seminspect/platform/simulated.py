"""The simulated robot behind the :class:`~seminspect.platform.protocol.Platform` protocol: a
:class:`Robot` with a camera, a detector (:mod:`seminspect.sensors.detector`) and a LiDAR in a
:class:`World`."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.params import InspectionParams
from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import (
    as_point,
    quat_from_yaw_pitch,
    reframe_points,
    wrap_angle,
    yaw_rotation,
)
from seminspect.platform.protocol import Motion
from seminspect.robot import Robot
from seminspect.robot.robot import MoveResult
from seminspect.sensors import CameraModel, Detection, Frame, Lidar, LidarScan, render
from seminspect.sensors.detector import Detector, TruthDetector, reads_image
from seminspect.sensors.noise import NoiseModel, NormalStream, make_noise
from seminspect.sensors.segmentation import as_level
from seminspect.worlds import World


class SimulatedPlatform:
    """A :class:`Robot` with a camera, a segmentation model and a LiDAR in a :class:`World`.

    Motion commands and everything the platform reports are in the robot's odometry frame,
    which drifts from the truth when the noise model says so. The camera is rendered from the
    true pose ``image_time_offset_s`` in the past and tagged with the current odometry (the
    image/odometry desync of 000 Sec VII-B). Before each image the robot stands still for
    ``settle_s`` (stop-and-shoot), which removes the desync error for images taken at rest.
    A robot of a team has a ``name``: its noise is drawn from random streams of its own.
    """

    def __init__(
        self,
        world: World,
        params: InspectionParams,
        *,
        mode: str,
        noise: NoiseModel,
        seed: int,
        radius: float,
        speed: float,
        yaw_rate: float,
        body_height: float,
        camera_pitch: float = 0.0,
        settle_s: float = 0.2,
        capture_s: float = 0.1,
        name: str | None = None,
        threads: int = 1,
        detector: Detector | None = None,
    ) -> None:
        # A named robot (one of a team) draws its noise from streams of its own.
        streams = () if name is None else (name,)
        self.world = world
        #: Threads the camera and the LiDAR cast their rays on (the same results on any number).
        self.threads = threads
        self.camera_pitch = camera_pitch
        self.noise = noise
        self.settle_s = settle_s
        self.capture_s = capture_s
        self.camera = CameraModel.from_params(params)
        self.lidar = Lidar(max_range=params.d_max)
        drift = noise.odometry_drift_per_m or noise.odometry_drift_per_rad
        self.robot = Robot(
            world,
            mode,  # type: ignore[arg-type]
            radius=radius,
            body_height=body_height,
            v_max=speed,
            yaw_rate_max=yaw_rate,
            odometry_drift_per_m=noise.odometry_drift_per_m,
            odometry_drift_per_rad=noise.odometry_drift_per_rad,
            rng=make_rng(seed, "robot", "odometry", *streams) if drift else None,
        )
        # The camera's noise is drawn ahead, off the mission's thread (the same numbers).
        self._camera_rng = NormalStream(make_rng(seed, "sensors", "camera", *streams), threads)
        #: What segments the camera's frames (the simulator's labels unless given).
        self.detector: Detector = detector or TruthDetector(
            world, noise, make_rng(seed, "sensors", "segmentation", *streams)
        )
        self._lidar_rng = make_rng(seed, "sensors", "lidar", *streams)
        self.frames = 0
        self.scans = 0
        self.blocked_moves = 0

    # ----------------------------------------------------------------- state (odometry frame)
    @property
    def time(self) -> float:
        return self.robot.time

    @property
    def position(self) -> NDArray[np.float64]:
        return self.robot.odometry_position

    @property
    def yaw(self) -> float:
        return self.robot.odometry_yaw

    @property
    def distance_travelled(self) -> float:
        return self.robot.distance_travelled

    def trajectory_rows(self) -> NDArray[np.float64]:
        trajectory = self.robot.trajectory
        return np.column_stack(
            [
                trajectory.time,
                trajectory.position,
                trajectory.yaw,
                trajectory.odometry_position,
                trajectory.odometry_yaw,
            ]
        )

    # ----------------------------------------------------------------- motion
    def _to_true(self, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """Where the robot really goes when it aims for ``point`` in its odometry frame."""
        robot = self.robot
        return reframe_points(
            point, robot.odometry_position, robot.odometry_yaw, robot.position, robot.yaw
        )

    def move_to(self, point: ArrayLike, yaw: float | None = None) -> Motion:
        goal = as_point(point if len(np.ravel(point)) == 3 else [*np.ravel(point), 0.0])
        if self.robot.mode == "ground":
            goal[2] = self.robot.odometry_position[2]
        true_yaw = (
            None if yaw is None else wrap_angle(yaw + self.robot.yaw - self.robot.odometry_yaw)
        )
        target = self._to_true(goal)
        result: MoveResult = self.robot.move_to(target, true_yaw)
        contact = None
        if result.blocked:
            self.blocked_moves += 1
            heading = target - result.position
            length = float(np.linalg.norm(heading))
            if length > 1e-9:  # the obstacle lies one body radius ahead of where it stopped
                touch = result.position + heading / length * self.robot.radius
                contact = self._to_odometry(touch)
        return Motion(result.reached, result.blocked, result.distance, contact)

    def _to_odometry(self, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """The inverse of :meth:`_to_true`: a true point in the robot's odometry frame."""
        robot = self.robot
        return reframe_points(
            point, robot.position, robot.yaw, robot.odometry_position, robot.odometry_yaw
        )

    def turn_to(self, yaw: float) -> Motion:
        return self.move_to(self.position, yaw)

    def wait(self, seconds: float) -> None:
        """Stand still for ``seconds`` (e.g. while a planner thinks)."""
        self.robot.wait(seconds)

    # ----------------------------------------------------------------- sensing
    def capture(self, intensity: bool = True) -> Frame:
        """Stop, then take one 640x480 depth + segmentation (+ intensity) frame; always with
        its intensity when the detector reads images (it sees every frame the program does)."""
        if self.settle_s:
            self.robot.wait(self.settle_s)
        late, now = self.robot.sensor_poses(self.noise.image_time_offset_s)
        frame = render(
            self.world,
            self.camera,
            late.position,
            self._camera_quaternion(late.yaw),
            noise=self.noise,
            rng=self._camera_rng,
            stamp=now.time,
            odometry=(now.odometry_position, self._camera_quaternion(now.odometry_yaw)),
            threads=self.threads,
            intensity=intensity or reads_image(self.detector),
        )
        self.robot.wait(self.capture_s)
        self.frames += 1
        return frame

    def _camera_quaternion(self, yaw: float) -> NDArray[np.float64]:
        """The camera looks along the heading, tilted down by ``camera_pitch``."""
        return quat_from_yaw_pitch(yaw, self.camera_pitch)

    def detect(self, frame: Frame, level: str, labels: Iterable[str]) -> list[Detection]:
        """Segment objects (``level="instance"``, by class) or parts (``"part"``, by part name)."""
        return self.detector.detect(frame, as_level(level), tuple(labels))

    def scan(self) -> LidarScan:
        """A LiDAR scan, expressed in the robot's odometry frame."""
        state = self.robot.state
        scan = self.lidar.scan(
            self.world,
            state.position,
            state.quaternion,
            noise=self.noise,
            rng=self._lidar_rng,
            stamp=state.time,
            threads=self.threads,
        )
        self.scans += 1
        scan.points = reframe_points(
            scan.points, state.position, state.yaw, state.odometry_position, state.odometry_yaw
        )
        turn = yaw_rotation(state.odometry_yaw - state.yaw)
        scan.misses = turn.apply(scan.misses.astype(np.float64)).astype(np.float32)
        scan.origin = state.odometry_position.copy()
        return scan


def mission_noise(name: str, drift_per_m: float | None) -> NoiseModel:
    """The sensor noise preset, with the drift of the mission's localisation.

    The ``realistic`` sensor preset drifts like wheel odometry (0.02 m per sqrt(m), and a
    heading random walk that the position error then integrates). The paper's robot localises
    with LIO-SAM, LiDAR-inertial odometry that registers every scan to its map and so does not
    accumulate heading error. By default a mission keeps only a small position random walk,
    0.003 m per sqrt(m), for ``realistic`` noise (none for ``ideal``). A value given by the user
    replaces it and restores the preset's heading drift, to study odometry-grade localisation.
    """
    base = make_noise({}, base=name)
    if drift_per_m is None:
        drift = 0.003 if base.odometry_drift_per_m else 0.0
        return make_noise({"odometry_drift_per_m": drift, "odometry_drift_per_rad": 0.0}, base=name)
    return make_noise({"odometry_drift_per_m": drift_per_m}, base=name)
