"""Every hyper-parameter of a recurrent PPO run of 004's policy (:mod:`.ppo`), validated.

Apart from the trainer so that a checkpoint (:mod:`.checkpoints`), which keeps the settings it
was trained with, and the recipes can read them without the training loop.
"""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, model_validator


class TrainConfig(BaseModel):
    """Every hyper-parameter of a training run (counts strict: a bool or a string is refused,
    not read as 1 or parsed, e.g. in a checkpoint's recorded settings)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    total_steps: int = Field(
        2_000_000, gt=0, strict=True, description="environment steps, all envs together"
    )
    num_envs: int = Field(64, gt=0, strict=True)
    rollout_steps: int = Field(32, gt=0, strict=True, description="steps per env between updates")
    epochs: int = Field(4, gt=0, strict=True)
    minibatches: int = Field(4, gt=0, strict=True, description="env-sequence minibatches per epoch")
    lr: float = Field(3e-4, gt=0)
    anneal_lr: bool = True
    gamma: float = Field(0.99, gt=0, le=1)
    gae_lambda: float = Field(0.95, ge=0, le=1)
    clip: float = Field(0.2, gt=0)
    ent_coef: float = Field(0.0, ge=0)
    vf_coef: float = Field(0.5, ge=0)
    max_grad_norm: float = Field(0.5, gt=0)
    normalize_rewards: bool = True
    #: (fraction of training, obstacle count) steps; empty: leave the env's own count.
    curriculum: tuple[tuple[float, int], ...] = ((0.0, 0), (0.25, 4), (0.5, 9))
    checkpoint_every: int = Field(100_000, gt=0, strict=True, description="environment steps")
    seed: int = Field(0, ge=0, strict=True)
    init_from: str | None = Field(
        None,
        description="SHA-256 of the checkpoint whose weights the run started from (a fine-tune); "
        "None: fresh weights",
    )
    threads: int = Field(
        1, gt=0, strict=True, description="torch threads (the envs share the cores)"
    )

    @model_validator(mode="after")
    def _check(self) -> TrainConfig:
        if self.num_envs % self.minibatches:
            raise ValueError(
                f"num_envs ({self.num_envs}) must be a multiple of minibatches "
                f"({self.minibatches}): minibatches are whole env sequences"
            )
        fractions = [fraction for fraction, _ in self.curriculum]
        if any(not 0 <= f < 1 for f in fractions) or fractions != sorted(set(fractions)):
            raise ValueError(f"curriculum fractions must rise within [0, 1), got {fractions}")
        if any(count < 0 for _, count in self.curriculum):
            raise ValueError("curriculum obstacle counts must be >= 0")
        return self

    @property
    def steps_per_update(self) -> int:
        return self.num_envs * self.rollout_steps

    @property
    def updates(self) -> int:
        return math.ceil(self.total_steps / self.steps_per_update)

    def obstacles_at(self, fraction: float) -> int | None:
        """The curriculum's obstacle count at this fraction of training (None: no curriculum
        step reached yet)."""
        reached = [count for start, count in self.curriculum if start <= fraction]
        return reached[-1] if reached else None
