"""The named training runs: networks, rooms and PPO settings."""

from __future__ import annotations

import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.recipes import (
    TRAINING_EPISODE_SECONDS,
    VARIANTS,
    policy_config,
    train_config,
    training_env_config,
)


def test_variants_ablate_one_part_each() -> None:
    main = policy_config("small", "main")
    assert main.use_svs and main.gru_size == 128
    assert not policy_config("small", "no-svs").use_svs
    assert policy_config("small", "no-gru").gru_size == 0
    assert policy_config("paper", "main").gru_size == 512
    assert set(VARIANTS) == {"main", "no-svs", "no-gru"}


def test_training_rooms_follow_the_network() -> None:
    env = training_env_config(policy_config("small", "no-svs"))
    assert not env.use_svs
    assert env.episode_seconds == TRAINING_EPISODE_SECONDS
    assert training_env_config(policy_config()).use_svs


def test_only_budget_and_seed_vary_between_runs() -> None:
    a, b = train_config(1000, seed=0), train_config(5000, seed=3)
    assert a.model_dump(exclude={"total_steps", "seed"}) == b.model_dump(
        exclude={"total_steps", "seed"}
    )
    assert [count for _, count in a.curriculum] == [0, 4, 9]


@pytest.mark.parametrize(("size", "variant"), [("small", "gru1024"), ("huge", "main")])
def test_unknown_names_are_refused(size: str, variant: str) -> None:
    with pytest.raises(InvalidInputError):
        policy_config(size, variant)  # type: ignore[arg-type]
