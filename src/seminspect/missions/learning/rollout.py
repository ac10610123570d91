"""What one PPO rollout holds, and what the trainer computes from it on the way.

A rollout is ``rollout_steps`` x ``num_envs`` transitions with the GRU state they started from;
from it come generalised advantage estimates (GAE), and while it is collected the rewards are
scaled by a running deviation of the return and timed-out episodes are bootstrapped from
their last observations.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import torch
from torch import Tensor

from seminspect.missions.learning.policy import ACTION_SIZE, DEPTH_SHAPE, MAPS_SHAPE, STATE_SIZE


@dataclasses.dataclass
class Rollout:
    """``rollout_steps`` x ``num_envs`` transitions, tensors with leading dims (T, N)."""

    obs: dict[str, Tensor]
    starts: Tensor  # 1.0 where the observation begins an episode
    raw_actions: Tensor  # (T, N, 4) unclipped Gaussian samples
    log_probs: Tensor
    values: Tensor
    rewards: Tensor  # scaled, with timeouts bootstrapped
    hidden0: Tensor  # (N, H) recurrent state before the first step
    next_value: Tensor = dataclasses.field(init=False)
    next_start: Tensor = dataclasses.field(init=False)

    @classmethod
    def empty(
        cls, steps: int, envs: int, hidden: int, device: torch.device | None = None
    ) -> Rollout:
        shapes = {"state": (STATE_SIZE,), "depth": DEPTH_SHAPE, "maps": MAPS_SHAPE}

        def zeros(*shape: int) -> Tensor:
            return torch.zeros(*shape, device=device)

        return cls(
            obs={key: zeros(steps, envs, *shape) for key, shape in shapes.items()},
            starts=zeros(steps, envs),
            raw_actions=zeros(steps, envs, ACTION_SIZE),
            log_probs=zeros(steps, envs),
            values=zeros(steps, envs),
            rewards=zeros(steps, envs),
            hidden0=zeros(envs, hidden),
        )


def advantages_gae(rollout: Rollout, gamma: float, lam: float) -> tuple[Tensor, Tensor]:
    """Generalised advantage estimates and returns (T, N). ``starts[t + 1]`` ends the episode
    of step t: no value flows back across it."""
    steps = rollout.rewards.shape[0]
    advantages = torch.zeros_like(rollout.rewards)
    running = torch.zeros_like(rollout.next_value)
    for t in reversed(range(steps)):
        if t == steps - 1:
            following, next_value = rollout.next_start, rollout.next_value
        else:
            following, next_value = rollout.starts[t + 1], rollout.values[t + 1]
        alive = 1.0 - following
        delta = rollout.rewards[t] + gamma * next_value * alive - rollout.values[t]
        running = delta + gamma * lam * alive * running
        advantages[t] = running
    return advantages, advantages + rollout.values


class ReturnScaler:
    """Divide rewards by a running standard deviation of the discounted return."""

    def __init__(self, envs: int, gamma: float):
        self.gamma = gamma
        self.returns = np.zeros(envs)
        self.count, self.mean, self.var = 1e-4, 0.0, 1.0

    def __call__(self, rewards: np.ndarray, done: np.ndarray) -> np.ndarray:
        self.returns = self.returns * self.gamma + rewards
        self._update(self.returns)
        self.returns[done] = 0.0
        return rewards / math.sqrt(self.var + 1e-8)

    def _update(self, batch: np.ndarray) -> None:
        # Chan et al.'s parallel mean/variance update
        n, mean, var = batch.size, float(batch.mean()), float(batch.var())
        total = self.count + n
        delta = mean - self.mean
        self.mean += delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total


def final_observations(info: Mapping[str, Any], rows: np.ndarray) -> dict[str, np.ndarray]:
    """The last observations of the episodes in ``rows`` from ``info["final_obs"]``: a dict
    of (num_envs, ...) arrays, or of per-env object arrays (Gymnasium's own vector envs)."""
    final = info["final_obs"]
    picked = {}
    for key in ("state", "depth", "maps"):
        column = np.asarray(final[key])
        picked[key] = np.stack(list(column[rows])) if column.dtype == object else column[rows]
    return picked
