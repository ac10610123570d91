"""Rollout storage: GAE on a hand-made rollout, final observations in both layouts."""

from __future__ import annotations

import numpy as np
import torch

from fake_vector_env import TargetReachEnv
from seminspect.missions.learning.rollout import Rollout, advantages_gae, final_observations


def test_gae_on_a_hand_made_rollout() -> None:
    rollout = Rollout.empty(steps=3, envs=1, hidden=0)
    rollout.rewards[:, 0] = torch.tensor([1.0, 2.0, 3.0])
    rollout.values[:, 0] = torch.tensor([0.5, 1.0, 1.5])
    rollout.starts[:, 0] = torch.tensor([1.0, 0.0, 1.0])  # step 1 ends an episode
    rollout.next_value, rollout.next_start = torch.tensor([2.0]), torch.tensor([0.0])
    gamma, lam = 0.9, 0.5
    delta2 = 3.0 + gamma * 2.0 - 1.5
    delta1 = 2.0 - 1.0  # no bootstrap across the episode's end
    delta0 = 1.0 + gamma * 1.0 - 0.5
    expected = torch.tensor([delta0 + gamma * lam * delta1, delta1, delta2])
    advantages, returns = advantages_gae(rollout, gamma, lam)
    torch.testing.assert_close(advantages[:, 0], expected)
    torch.testing.assert_close(returns, advantages + rollout.values)


def test_final_observations_in_either_layout() -> None:
    env = TargetReachEnv(3, seed=0)
    obs, _ = env.reset(seed=0)
    rows = np.array([False, True, True])
    stacked = final_observations({"final_obs": obs}, rows)
    per_env = {key: np.empty(3, dtype=object) for key in obs}
    for key, value in obs.items():
        for row in range(3):
            per_env[key][row] = value[row] if rows[row] else None
    from_objects = final_observations({"final_obs": per_env}, rows)
    for key in obs:
        np.testing.assert_array_equal(stacked[key], obs[key][1:])
        np.testing.assert_array_equal(from_objects[key], obs[key][1:])
