"""A trained policy driving the rooms, and the shipped checkpoint."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from seminspect.core.errors import FileFormatError
from seminspect.missions.learning.agent import (
    LearnedController,
    load_controller,
    shipped_policy_path,
)
from seminspect.missions.learning.checkpoints import save_checkpoint
from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig


def _rollout(controller: LearnedController, steps: int = 5) -> list[np.ndarray]:
    env = InspectionVectorEnv(3, EnvConfig(obstacles=2), seed=4)
    obs, _ = env.reset(seed=4)
    controller.reset(env)
    actions = []
    for _ in range(steps):
        action = controller.act(env, obs)
        actions.append(action)
        obs, *_ = env.step(action)
    return actions


def test_learned_controller_acts_in_range_and_repeats_itself() -> None:
    torch.manual_seed(0)
    controller = LearnedController(InspectionPolicy(PolicyConfig.small()), EnvConfig())
    first, second = _rollout(controller), _rollout(controller)
    assert first[0].shape == (3, 4)
    assert all(np.all(np.abs(a) <= 1.0) for a in first)
    assert all(np.array_equal(a, b) for a, b in zip(first, second, strict=True))


def test_missing_checkpoint_is_one_readable_error(tmp_path) -> None:
    with pytest.raises(FileFormatError, match="no such file"):
        load_controller(tmp_path / "absent.pt")


def test_shipped_policy_is_in_the_package() -> None:
    path = shipped_policy_path()
    assert path.is_file(), path
    controller = load_controller()
    assert controller.policy.config == PolicyConfig.small()
    assert controller.env_config == EnvConfig.legacy()  # policy v1 recorded no rooms


def test_a_controller_flies_in_the_rooms_its_checkpoint_records(tmp_path) -> None:
    rooms = EnvConfig(obstacles=5, target_shapes=("sphere",), use_svs=False)
    torch.manual_seed(0)
    policy = InspectionPolicy(PolicyConfig.small(use_svs=False))
    path = save_checkpoint(tmp_path / "p.pt", policy, None, steps=0, env_config=rooms)
    assert load_controller(path).env_config == rooms


def test_shipped_policy_covers_far_more_than_random_in_the_same_rooms() -> None:
    """Four fixed empty rooms of its own kind, 90 s episodes: learned against random actions."""
    from seminspect.missions.learning.baselines import RandomController
    from seminspect.missions.learning.evaluation import evaluate

    controller = load_controller()
    config = controller.env_config
    learned = evaluate(controller, [0], 4, 11, config=config, num_envs=4).at(0)
    random = evaluate(RandomController(11), [0], 4, 11, config=config, num_envs=4).at(0)
    assert learned.rooms == random.rooms
    assert learned.coverage_pct > random.coverage_pct + 30.0
    assert learned.crash_pct < random.crash_pct
