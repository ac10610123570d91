"""The training runs behind the shipped policy and the ablations of 004 Tables II and III.

One place names every run, so the CLI, the reproduction script and the docs agree on what was
trained: the network (:class:`PolicyConfig` preset plus the ablated part), the training rooms
and the PPO settings with the obstacle curriculum.
"""

from __future__ import annotations

from typing import Literal

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig

#: Network variants: the main policy (GRU 128) and the ablations of Table II (no SVS map) and
#: Table III (no GRU).
VARIANTS: dict[str, dict[str, object]] = {
    "main": {},
    "no-svs": {"use_svs": False},
    "no-gru": {"gru_size": 0},
}
#: Training episodes are half the paper's 90 s: the 10 x 10 m room is covered well within it,
#: and shorter episodes give more rooms per step of a small budget. Evaluation uses 90 s.
TRAINING_EPISODE_SECONDS = 45.0
#: Obstacles are introduced progressively (004 Sec IV-A): (fraction of training, count).
CURRICULUM = ((0.0, 0), (0.2, 4), (0.45, 9))


def policy_config(size: Literal["small", "paper"] = "small", variant: str = "main") -> PolicyConfig:
    """The network of a named run: the ``small`` (CPU) or ``paper`` preset with its ablation."""
    if variant not in VARIANTS:
        raise InvalidInputError(f"unknown variant {variant!r}; choose from {sorted(VARIANTS)}")
    if size not in ("small", "paper"):
        raise InvalidInputError(f"unknown network size {size!r}; choose small or paper")
    preset = PolicyConfig.small if size == "small" else PolicyConfig.paper
    return preset(**VARIANTS[variant])


def training_env_config(policy: PolicyConfig) -> EnvConfig:
    """Rooms for training a policy: the evaluation rooms with shorter episodes."""
    return EnvConfig(episode_seconds=TRAINING_EPISODE_SECONDS, use_svs=policy.use_svs)


def train_config(steps: int, seed: int = 0, num_envs: int = 64) -> TrainConfig:
    """PPO settings of every run (only the budget and the seed vary)."""
    return TrainConfig(
        total_steps=steps,
        num_envs=num_envs,
        rollout_steps=32,
        epochs=3,
        seed=seed,
        checkpoint_every=100_000,
        curriculum=CURRICULUM,
    )
