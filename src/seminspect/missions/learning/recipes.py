"""The training runs of 004's policy and of the ablations of its Tables II and III.

One place names every run, so the CLI, the reproduction script and the docs agree on what is
trained: the network (:class:`PolicyConfig` preset plus the ablated part), the training rooms,
the budgets and the PPO settings with the obstacle curriculum. (Policy v1, shipped, was trained
before these rooms, in ``EnvConfig.legacy(episode_seconds=45.0)``; policy v2 in these rooms with
f_t paid unshaped; v3 with the graded penalty alone, v4 adds the time-to-contact penalty. Each
checkpoint records the env config it was trained in.)
"""

from __future__ import annotations

from typing import Literal

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.env_config import PAPER_ROOM_RANGE, EnvConfig, TargetShape
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig

#: Network variants: the main policy (GRU 128) and the ablations of Table II (no SVS map) and
#: Table III (no GRU, and the paper's larger GRU 512).
VARIANTS: dict[str, dict[str, object]] = {
    "main": {},
    "no-svs": {"use_svs": False},
    "no-gru": {"gru_size": 0},
    "gru-512": {"gru_size": 512},
}
#: Budgets in environment steps: the main policy and each ablation (Tables II and III).
MAIN_STEPS = 5_000_000
ABLATION_STEPS = 2_000_000
BUDGETS: dict[str, int] = {"main": MAIN_STEPS} | {
    variant: ABLATION_STEPS for variant in ("no-svs", "no-gru", "gru-512")
}
#: The object's shapes in training: 004 Sec III-E's primitives. The T-pipe is held out: 004
#: Sec V meets it unseen, and so does our generalisation table.
TRAINING_SHAPES: tuple[TargetShape, ...] = ("cylinder", "box", "sphere")
#: 004 Sec IV-A sets up an obstacle curriculum without giving its schedule; this one is ours:
#: (fraction of training, obstacle count), ending at the paper's nine.
CURRICULUM = ((0.0, 0), (0.2, 4), (0.45, 9))
#: A fine-tune starts from a policy trained through the curriculum: the paper's nine at once.
FINE_TUNE_CURRICULUM = ((0.0, 9),)
#: PPO's discount, and so the potential of the shaped face reward (EnvConfig.shaping_discount).
DISCOUNT = 0.99


def policy_config(size: Literal["small", "paper"] = "small", variant: str = "main") -> PolicyConfig:
    """The network of a named run: the ``small`` (CPU) or ``paper`` preset with its ablation."""
    if variant not in VARIANTS:
        raise InvalidInputError(f"unknown variant {variant!r}; choose from {sorted(VARIANTS)}")
    if size not in ("small", "paper"):
        raise InvalidInputError(f"unknown network size {size!r}; choose small or paper")
    preset = PolicyConfig.small if size == "small" else PolicyConfig.paper
    return preset(**VARIANTS[variant])


def training_env_config(policy: PolicyConfig) -> EnvConfig:
    """004 Sec III-E's training rooms: sizes drawn from PAPER_ROOM_RANGE, 90 s episodes, the
    training shapes; the SVS map as the network has it (Table II's ablation has none); f_t
    shaped for the trainer's discount; p_t graded and by time to contact (policy v3 crashed
    into obstacles its map showed, at a median 1.3 m/s: the graded zone is crossed in 2-3
    steps at that speed)."""
    return EnvConfig(
        room_size_range=PAPER_ROOM_RANGE,
        episode_seconds=90.0,
        target_shapes=TRAINING_SHAPES,
        use_svs=policy.use_svs,
        shaping_discount=DISCOUNT,
        proximity_penalty="contact",
    )


def train_config(
    steps: int, seed: int = 0, num_envs: int = 64, init_from: str | None = None
) -> TrainConfig:
    """PPO settings of every run (only the budget and the seed vary); a fine-tune of the
    checkpoint with SHA-256 ``init_from`` flies nine obstacles from its first step."""
    return TrainConfig(
        total_steps=steps,
        num_envs=num_envs,
        rollout_steps=32,
        epochs=3,
        gamma=DISCOUNT,
        seed=seed,
        checkpoint_every=100_000,
        curriculum=CURRICULUM if init_from is None else FINE_TUNE_CURRICULUM,
        init_from=init_from,
    )
