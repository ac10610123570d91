"""A holonomic robot body with velocity limits, collisions, odometry drift and a trajectory log.

The robot is a point with a heading and a radius. Motions are straight lines at constant speed
while the heading turns at constant rate; a motion takes ``max(distance / v_max, |turn| /
yaw_rate_max)`` seconds, so time advances analytically with no stepping. Before moving the body
is swept along the segment through the world's collision field; if it would touch a surface it
stops at the last free point and the result says where it was blocked.

``ground`` mode is a legged robot: its camera stays ``body_height`` above the ground and it
cannot inspect vertically (000 Sec VI-A). ``aerial`` mode flies between ``z_min`` and ``z_max``.

Odometry integrates the true motion with the current heading error and adds a random walk whose
variance grows with the distance moved and the angle turned. The log keeps both poses, and
:meth:`Robot.pose_at` interpolates it: render at the true pose of ``t - offset`` and tag the frame
with the odometry of ``t`` to simulate the image/odometry desync of 000 Sec VII-B.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import (
    Quat,
    Vec3,
    as_point,
    quat_from_yaw,
    quat_from_yaw_pitch,
    wrap_angle,
)
from seminspect.worlds import World

Mode = Literal["ground", "aerial"]


@dataclass(frozen=True)
class RobotState:
    """True and odometry pose at one time."""

    time: float
    position: Vec3
    yaw: float
    odometry_position: Vec3
    odometry_yaw: float

    @property
    def quaternion(self) -> Quat:
        return quat_from_yaw(self.yaw)

    @property
    def odometry_quaternion(self) -> Quat:
        return quat_from_yaw(self.odometry_yaw)


@dataclass(frozen=True)
class MoveResult:
    """Outcome of a motion command.

    Attributes:
        reached: the robot arrived where it was sent.
        blocked: a surface stopped it; it stands at the last free point.
        position: where it stands now (true position).
        blocked_at: the first point along the path that would have touched a surface.
        duration: seconds the motion took.
        distance: metres travelled.
        waypoints_reached: waypoints completed (``follow``); 1 or 0 for a single motion.
    """

    reached: bool
    blocked: bool
    position: Vec3
    blocked_at: Vec3 | None = None
    duration: float = 0.0
    distance: float = 0.0
    waypoints_reached: int = 0


@dataclass
class _Log:
    time: list[float] = field(default_factory=list)
    position: list[Vec3] = field(default_factory=list)
    yaw: list[float] = field(default_factory=list)  # unwrapped, so it interpolates linearly
    odometry_position: list[Vec3] = field(default_factory=list)
    odometry_yaw: list[float] = field(default_factory=list)


@dataclass(frozen=True)
class Trajectory:
    """The robot's log as arrays (yaw unwrapped, radians)."""

    time: NDArray[np.float64]
    position: NDArray[np.float64]
    yaw: NDArray[np.float64]
    odometry_position: NDArray[np.float64]
    odometry_yaw: NDArray[np.float64]


class Robot:
    """A holonomic ground or aerial robot in a world.

    Args:
        world: the world it moves in (collisions use ``world.collision``).
        mode: ``"ground"`` (fixed height, horizontal motion only) or ``"aerial"``.
        radius: body radius for collision checks (metres).
        body_height: camera height above the ground in ground mode, and the take-off height in
            aerial mode (metres).
        v_max: speed limit (m/s); 1 m/s as the velocity limit of 004 Sec III-D.
        yaw_rate_max: turn-rate limit (rad/s); 1 rad/s as in 004 Sec III-D.
        z_min, z_max: altitude limits in aerial mode (``z_max`` defaults to the world's top
            minus the radius).
        odometry_drift_per_m, odometry_drift_per_rad: random-walk drift, see ``NoiseModel``.
        rng: generator for the drift; required when a drift is non-zero.
        position, yaw: start pose (default: the world's start, lifted by ``body_height``).
    """

    def __init__(
        self,
        world: World,
        mode: Mode = "ground",
        *,
        radius: float = 0.4,
        body_height: float = 0.7,
        v_max: float = 1.0,
        yaw_rate_max: float = 1.0,
        z_min: float = 0.5,
        z_max: float | None = None,
        odometry_drift_per_m: float = 0.0,
        odometry_drift_per_rad: float = 0.0,
        rng: np.random.Generator | None = None,
        position: ArrayLike | None = None,
        yaw: float | None = None,
    ) -> None:
        if mode not in ("ground", "aerial"):
            raise InvalidInputError(f"robot mode must be 'ground' or 'aerial', got {mode!r}")
        for name, value in (
            ("radius", radius),
            ("body height", body_height),
            ("v_max", v_max),
            ("yaw_rate_max", yaw_rate_max),
        ):
            if not (math.isfinite(value) and value > 0):
                raise InvalidInputError(f"robot {name} must be > 0, got {value}")
        if odometry_drift_per_m < 0 or odometry_drift_per_rad < 0:
            raise InvalidInputError("odometry drift must be >= 0")
        if (odometry_drift_per_m or odometry_drift_per_rad) and rng is None:
            raise InvalidInputError(
                "odometry drift needs a random generator: pass rng=make_rng(...)"
            )
        self.world = world
        self.mode: Mode = mode
        self.radius = float(radius)
        self.body_height = float(body_height)
        self.v_max = float(v_max)
        self.yaw_rate_max = float(yaw_rate_max)
        self.z_min = float(z_min)
        self.z_max = float(world.bounds[1, 2] - radius if z_max is None else z_max)
        self.drift = (float(odometry_drift_per_m), float(odometry_drift_per_rad))
        self._rng = rng
        if position is None:
            point = world.start_position.copy()
            point[2] += body_height
        else:
            point = as_point(position, "robot start position")
        self._check_target(point)
        if not self._free(point):
            raise InvalidInputError(_blocked_start(world, point, mode))
        heading = world.start_yaw if yaw is None else float(yaw)
        self._log = _Log()
        self._record(0.0, point, heading, point.copy(), heading)
        self.distance_travelled = 0.0

    # ----------------------------------------------------------------- state
    @property
    def time(self) -> float:
        """Simulated clock (seconds since the start)."""
        return self._log.time[-1]

    @property
    def position(self) -> Vec3:
        """True position (metres)."""
        return self._log.position[-1].copy()

    @property
    def yaw(self) -> float:
        """True heading in (-pi, pi]."""
        return wrap_angle(self._log.yaw[-1])

    @property
    def quaternion(self) -> Quat:
        return quat_from_yaw(self.yaw)

    @property
    def odometry_position(self) -> Vec3:
        """Position the robot believes it has."""
        return self._log.odometry_position[-1].copy()

    @property
    def odometry_yaw(self) -> float:
        return wrap_angle(self._log.odometry_yaw[-1])

    @property
    def state(self) -> RobotState:
        return self.pose_at(self.time)

    @property
    def trajectory(self) -> Trajectory:
        log = self._log
        return Trajectory(
            np.array(log.time),
            np.array(log.position),
            np.array(log.yaw),
            np.array(log.odometry_position),
            np.array(log.odometry_yaw),
        )

    def camera_orientation(self, pitch: float = 0.0) -> Quat:
        """Camera quaternion: the body heading, tilted nose-down by ``pitch`` radians."""
        return quat_from_yaw_pitch(self.yaw, pitch)

    # ----------------------------------------------------------------- motion
    def move_to(self, point: ArrayLike, yaw: float | None = None) -> MoveResult:
        """Move in a straight line to ``point`` (x, y or x, y, z), turning to ``yaw`` on the way."""
        target = self._as_target(point)
        start = self.position
        heading = self._log.yaw[-1]
        turn = 0.0 if yaw is None else wrap_angle(float(yaw) - heading)
        sweep = self.world.collision.sweep(start, target, self.radius, self.mode)
        fraction = sweep.free_until
        duration = self._duration(float(np.linalg.norm(target - start)), turn)
        end = start + fraction * (target - start)
        self._advance(end, heading + fraction * turn, fraction * duration)
        blocked_at = None if sweep.contact is None else start + sweep.contact * (target - start)
        distance = float(np.linalg.norm(end - start))
        reached = sweep.contact is None
        return MoveResult(
            reached,
            not reached,
            self.position,
            blocked_at,
            fraction * duration,
            distance,
            int(reached),
        )

    def turn_to(self, yaw: float) -> MoveResult:
        """Turn on the spot to ``yaw`` at the turn-rate limit."""
        return self.move_to(self.position, yaw)

    def follow(
        self, waypoints: Sequence[ArrayLike], yaws: Sequence[float | None] | None = None
    ) -> MoveResult:
        """Visit waypoints in order; stop at the first motion that is blocked."""
        headings = list(yaws) if yaws is not None else [None] * len(waypoints)
        if len(headings) != len(waypoints):
            raise InvalidInputError(f"{len(headings)} yaws for {len(waypoints)} waypoints")
        duration = distance = 0.0
        result = MoveResult(True, False, self.position)
        for count, (point, heading) in enumerate(zip(waypoints, headings, strict=True)):
            result = self.move_to(point, heading)
            duration += result.duration
            distance += result.distance
            if not result.reached:
                return MoveResult(
                    False, True, result.position, result.blocked_at, duration, distance, count
                )
        return MoveResult(True, False, result.position, None, duration, distance, len(waypoints))

    def wait(self, seconds: float) -> None:
        """Stand still for ``seconds``."""
        if not (math.isfinite(seconds) and seconds >= 0):
            raise InvalidInputError(f"wait time must be >= 0, got {seconds}")
        self._advance(self.position, self._log.yaw[-1], seconds)

    # ----------------------------------------------------------------- log queries
    def pose_at(self, t: float) -> RobotState:
        """True and odometry pose at time ``t``, interpolated in the log (clamped to its span)."""
        if not math.isfinite(t):
            raise InvalidInputError(f"time must be finite, got {t}")
        log = self._log
        times = np.asarray(log.time)
        t = min(max(t, times[0]), times[-1])
        i = int(np.searchsorted(times, t, side="right")) - 1
        j = min(i + 1, len(times) - 1)
        span = times[j] - times[i]
        w = 0.0 if span <= 0 else (t - times[i]) / span

        def mix(values: list) -> NDArray | float:
            return (1 - w) * np.asarray(values[i]) + w * np.asarray(values[j])

        return RobotState(
            time=float(t),
            position=np.asarray(mix(log.position)),
            yaw=wrap_angle(float(mix(log.yaw))),
            odometry_position=np.asarray(mix(log.odometry_position)),
            odometry_yaw=wrap_angle(float(mix(log.odometry_yaw))),
        )

    def sensor_poses(self, image_time_offset_s: float) -> tuple[RobotState, RobotState]:
        """``(state at now - offset, state now)``: render with the first, tag with the second.

        The first state's true pose is where the camera really was when the (late) image was
        exposed; the second's odometry is what the robot attaches to it.
        """
        if not (math.isfinite(image_time_offset_s) and image_time_offset_s >= 0):
            raise InvalidInputError(f"time offset must be >= 0, got {image_time_offset_s}")
        return self.pose_at(self.time - image_time_offset_s), self.state

    # ----------------------------------------------------------------- internals
    def _free(self, point: Vec3) -> bool:
        return bool(self.world.is_free(point[None], self.radius, self.mode)[0])

    def _as_target(self, point: ArrayLike) -> Vec3:
        values = np.asarray(point, dtype=np.float64).reshape(-1)
        if values.shape == (2,):
            values = np.append(values, self.position[2])
        target = as_point(values, "target point")
        self._check_target(target)
        return target

    def _check_target(self, point: Vec3) -> None:
        if self.mode == "ground":
            height = self.world.ground_z + self.body_height
            if abs(point[2] - height) > 1e-6:
                raise InvalidInputError(
                    f"a ground robot keeps its camera at z = {height:.3f} m; "
                    f"it cannot move to z = {point[2]:.3f} m"
                )
        elif not (self.z_min <= point[2] <= self.z_max):
            limits = f"[{self.z_min:.3f}, {self.z_max:.3f}]"
            raise InvalidInputError(f"altitude {point[2]:.3f} m is outside the limits {limits} m")

    def _duration(self, distance: float, turn: float) -> float:
        return max(distance / self.v_max, abs(turn) / self.yaw_rate_max)

    def _advance(self, end: Vec3, heading: float, duration: float) -> None:
        log = self._log
        step = end - log.position[-1]
        turn = heading - log.yaw[-1]
        odom_position, odom_yaw = self._odometry_step(step, turn)
        self.distance_travelled += float(np.linalg.norm(step))
        self._record(log.time[-1] + duration, end, heading, odom_position, odom_yaw)

    def _odometry_step(self, step: Vec3, turn: float) -> tuple[Vec3, float]:
        """Dead-reckon ``step`` with the current heading error, then add the random walk."""
        log = self._log
        error = log.odometry_yaw[-1] - log.yaw[-1]
        c, s = math.cos(error), math.sin(error)
        moved = np.array([c * step[0] - s * step[1], s * step[0] + c * step[1], step[2]])
        position = log.odometry_position[-1] + moved
        heading = log.odometry_yaw[-1] + turn
        per_m, per_rad = self.drift
        if self._rng is not None and (per_m or per_rad):
            length = float(np.linalg.norm(step))
            axes = 2 if self.mode == "ground" else 3
            position[:axes] += self._rng.normal(0.0, per_m * math.sqrt(length), axes)
            heading += self._rng.normal(0.0, per_rad * math.sqrt(abs(turn)))
        return position, heading

    def _record(self, t: float, position: Vec3, yaw: float, odom: Vec3, odom_yaw: float) -> None:
        log = self._log
        log.time.append(float(t))
        log.position.append(np.asarray(position, dtype=np.float64).copy())
        log.yaw.append(float(yaw))
        log.odometry_position.append(np.asarray(odom, dtype=np.float64).copy())
        log.odometry_yaw.append(float(odom_yaw))


def _blocked_start(world: World, point: Vec3, mode: Mode) -> str:
    """Why a start that is not free is refused: outside the world's bounds (only x-y count for
    a ground robot, whose height the collision grid ignores) or inside an obstacle."""
    axes = 2 if mode == "ground" else 3
    lo, hi = world.bounds[:, :axes]
    where = f"robot start {point.round(3).tolist()}"
    if np.any((point[:axes] < lo) | (point[:axes] > hi)):
        which = "x-y bounds" if axes == 2 else "bounds"
        return (
            f"{where} is outside the world {world.name!r}, whose {which} are "
            f"{lo.round(3).tolist()} to {hi.round(3).tolist()}"
        )
    return f"{where} is inside an obstacle"
