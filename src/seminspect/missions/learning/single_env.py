"""One room of the 004 environment as a plain ``gymnasium.Env``.

A view of a one-room :class:`~seminspect.missions.learning.env.InspectionVectorEnv` without
autoreset, for tools that take a single environment (``gymnasium.utils.env_checker``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig


class InspectionEnv(gym.Env):
    """One room as a plain ``gymnasium.Env`` (no autoreset), for tools that want a single env."""

    metadata = {"render_modes": []}  # noqa: RUF012 - gymnasium API

    def __init__(self, config: EnvConfig | None = None, seed: int = 0) -> None:
        self._vector = InspectionVectorEnv(1, config, seed=seed, autoreset=False)
        self.observation_space = self._vector.single_observation_space
        self.action_space = self._vector.single_action_space

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, NDArray[np.float32]], dict[str, Any]]:
        super().reset(seed=seed)
        obs, info = self._vector.reset(seed=seed, options=options)
        return _row(obs), {"coverage": float(info["coverage"][0])}

    def step(
        self, action: NDArray
    ) -> tuple[dict[str, NDArray[np.float32]], float, bool, bool, dict[str, Any]]:
        obs, reward, crash, timeout, info = self._vector.step(np.asarray(action)[None])
        return (
            _row(obs),
            float(reward[0]),
            bool(crash[0]),
            bool(timeout[0]),
            {"coverage": float(info["coverage"][0])},
        )


def _row(obs: dict[str, NDArray[np.float32]]) -> dict[str, NDArray[np.float32]]:
    return {key: value[0] for key, value in obs.items()}
