"""A toy vector environment with the inspection environment's observations and info keys.

Each episode draws a target action a* in [-0.5, 0.5]^4 and shows it in ``state[:4]``; the
reward is ``-||a - a*||``, so a policy that reads the state learns it within seconds. An action
whose first component exceeds 0.95 is a "crash" (terminated); otherwise the episode times out
(truncated) after ``length`` steps. Same-step autoreset, ``info["final_obs"]``,
``info["episode"]`` and ``set_obstacles`` follow ``learning.env``'s contract; the obstacle
count fills that many voxels of the occupancy channel.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.missions.learning.policy import DEPTH_SHAPE, MAPS_SHAPE, STATE_SIZE


class TargetReachEnv:
    def __init__(self, num_envs: int, seed: int = 0, length: int = 8, crash_above: float = 0.95):
        self.num_envs, self.length, self.crash_above = num_envs, length, crash_above
        self.rng = make_rng(seed, "tests", "fake-vector-env")
        self.targets = np.zeros((num_envs, 4), np.float32)
        self.steps = np.zeros(num_envs, int)
        self.returns = np.zeros(num_envs)
        self.hits = np.zeros(num_envs)
        self.obstacles = np.zeros(num_envs, int)
        self.pending_obstacles: np.ndarray | None = None
        self.obstacle_calls: list[int] = []
        self.closed = False

    def set_obstacles(self, counts: int) -> None:
        self.obstacle_calls.append(int(counts))
        self.pending_obstacles = np.broadcast_to(np.asarray(counts, int), (self.num_envs,))

    def reset(self, *, seed: int | None = None) -> tuple[dict[str, np.ndarray], dict]:
        if seed is not None:
            self.rng = make_rng(seed, "tests", "fake-vector-env")
        for row in range(self.num_envs):
            self._new_episode(row)
        return self._observe(np.zeros((self.num_envs, 4), np.float32)), {}

    def _new_episode(self, row: int) -> None:
        self.targets[row] = self.rng.uniform(-0.5, 0.5, 4)
        self.steps[row] = self.returns[row] = self.hits[row] = 0
        if self.pending_obstacles is not None:
            self.obstacles[row] = self.pending_obstacles[row]

    def _observe(self, actions: np.ndarray) -> dict[str, np.ndarray]:
        state = np.zeros((self.num_envs, STATE_SIZE), np.float32)
        state[:, :4] = self.targets
        state[:, 13:] = actions
        maps = np.zeros((self.num_envs, *MAPS_SHAPE), np.float32)
        for row, count in enumerate(self.obstacles):
            maps[row, 0].reshape(-1)[:count] = 1.0
        depth = np.full((self.num_envs, *DEPTH_SHAPE), 0.5, np.float32)
        return {"state": state, "depth": depth, "maps": maps}

    def step(self, actions: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray, Any, Any, dict]:
        assert actions.shape == (self.num_envs, 4) and np.all(np.abs(actions) <= 1.0)
        error = np.linalg.norm(actions - self.targets, axis=1)
        terminated = actions[:, 0] > self.crash_above
        reward = np.where(terminated, -1.0, 1.0 - error / 3.0).astype(np.float32)
        self.steps += 1
        self.returns += reward
        self.hits += error < 0.5
        truncated = ~terminated & (self.steps >= self.length)
        done = terminated | truncated
        info: dict[str, Any] = {}
        if done.any():
            info["final_obs"] = self._observe(actions)
            info["_final_obs"] = done.copy()
            info["episode"] = {
                "return": self.returns.copy(),
                "length": self.steps.copy(),
                "coverage": self.hits / np.maximum(self.steps, 1),
                "crash": terminated.copy(),
                "timeout": truncated.copy(),
            }
            info["_episode"] = done.copy()
            for row in np.flatnonzero(done):
                self._new_episode(row)
        previous = np.where(done[:, None], 0.0, actions).astype(np.float32)
        return self._observe(previous), reward, terminated, truncated, info

    def close(self) -> None:
        self.closed = True
