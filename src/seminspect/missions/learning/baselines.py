"""Reference behaviours in the learned policy's rooms: a random policy and a semantic orbit.

Both follow the :class:`Controller` protocol that evaluation drives, like the learned policy.
The orbit is a hand-written inspection: it knows where the semantic object stands (privileged,
as a perfect detector would give) but not where the obstacles are, flies to the reference
distance d_ref from the object's axis, faces it, and circles it twice: once at mid height for
the side, once above its top for the cap. It is the natural yardstick for a learned policy: it
covers an empty room almost fully and says nothing about clutter.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import body_from_world
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import ACTION_SIZE


class Controller(Protocol):
    """Anything that turns the environments' observations into actions."""

    def reset(self, env: InspectionVectorEnv) -> None:
        """Called once after ``env.reset``, before the first action of an evaluation."""

    def act(self, env: InspectionVectorEnv, obs: dict[str, NDArray[np.float32]]) -> NDArray:
        """Actions ``(num_envs, 4)`` in [-1, 1] for the current observations."""


class RandomController:
    """Uniform random actions, seeded."""

    def __init__(self, seed: int = 0) -> None:
        self._seed = seed
        self._rng = make_rng(seed, "learning", "random-policy")

    def reset(self, env: InspectionVectorEnv) -> None:
        self._rng = make_rng(self._seed, "learning", "random-policy")

    def act(self, env: InspectionVectorEnv, obs: dict[str, NDArray[np.float32]]) -> NDArray:
        return self._rng.uniform(-1.0, 1.0, (env.num_envs, ACTION_SIZE)).astype(np.float32)


class OrbitController:
    """Circle the semantic object at d_ref, first at mid height, then above its top.

    Args:
        gain: proportional gain from position error (m) to commanded speed (fraction of w_max).
        above_top: height of the second loop over the object's top (m).
        distance: how far from the object's horizontal extent to circle (m); None: d_ref.
    """

    def __init__(
        self, gain: float = 1.5, above_top: float = 0.6, distance: float | None = None
    ) -> None:
        self.gain = gain
        self.above_top = above_top
        self.distance = distance
        self._swept = np.zeros(0)
        self._last_angle = np.zeros(0)

    def reset(self, env: InspectionVectorEnv) -> None:
        self._swept = np.zeros(env.num_envs)
        self._last_angle = np.full(env.num_envs, np.nan)

    def act(self, env: InspectionVectorEnv, obs: dict[str, NDArray[np.float32]]) -> NDArray:
        cfg = env.config
        position, yaw = env.positions(), env.yaws()
        rooms = env.rooms
        bound = np.array([room.target_box for room in rooms])
        centre = bound.mean(axis=1)
        offset = position[:, :2] - centre[:, :2]
        angle = np.arctan2(offset[:, 1], offset[:, 0])
        step = np.angle(
            np.exp(1j * (angle - np.where(np.isnan(self._last_angle), angle, self._last_angle)))
        )
        self._swept += np.abs(step)
        self._last_angle = angle
        standoff = cfg.d_ref if self.distance is None else self.distance
        radius = np.array([room.target_radius for room in rooms]) + standoff
        distance = np.linalg.norm(offset, axis=1)
        outward = offset / np.maximum(distance, 1e-6)[:, None]
        tangent = np.stack([-outward[:, 1], outward[:, 0]], axis=1)
        top = bound[:, 1, 2]
        height = np.where(self._swept < 2 * math.pi, centre[:, 2], top + self.above_top)
        height = np.minimum(height, np.array([room.size[2] for room in rooms]) - 0.5)
        command = np.zeros((env.num_envs, 3))
        command[:, :2] = self.gain * (radius - distance)[:, None] * outward + 0.6 * tangent
        command[:, 2] = self.gain * (height - position[:, 2])
        body = body_from_world(command, yaw) / cfg.max_speed
        facing = np.angle(np.exp(1j * (angle + math.pi - yaw)))
        yaw_rate = 2.0 * facing / cfg.max_yaw_rate
        return np.clip(np.column_stack([body, yaw_rate]), -1.0, 1.0).astype(np.float32)
