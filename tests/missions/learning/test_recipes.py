"""The named training runs: networks, rooms and PPO settings."""

from __future__ import annotations

import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.env_config import PAPER_ROOM_RANGE, TARGET_SHAPES
from seminspect.missions.learning.recipes import (
    BUDGETS,
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
    assert policy_config("small", "gru-512").gru_size == 512  # Table III's larger GRU
    assert policy_config("small", "gru-512").use_svs
    assert policy_config("paper", "main").gru_size == 512
    assert set(VARIANTS) == {"main", "no-svs", "no-gru", "gru-512"}


def test_training_rooms_are_004s_and_follow_the_network() -> None:
    env = training_env_config(policy_config("small", "no-svs"))
    assert not env.use_svs
    assert training_env_config(policy_config()).use_svs
    # 004 Sec III-E: rooms of [4, 20] x [4, 20] x [2, 8] m, 90 s episodes, primitive objects
    assert env.room_size_range == PAPER_ROOM_RANGE and env.episode_seconds == 90.0
    assert set(env.target_shapes) == set(TARGET_SHAPES) - {"t-pipe"}  # held out, as in Sec V
    assert env.face_reward == "fraction" and env.yaw_encoding == "full-angle"  # not policy v1's
    assert env.shaping_discount == train_config(1000).gamma  # shaped for the trainer's discount
    assert env.proximity_penalty == "contact"  # policy v4's (v3: graded)


def test_the_budgets_are_5_m_steps_for_the_policy_and_2_m_per_ablation() -> None:
    ablations = dict.fromkeys(("no-svs", "no-gru", "gru-512"), 2_000_000)
    assert {"main": 5_000_000, **ablations} == BUDGETS
    assert set(BUDGETS) == set(VARIANTS)


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


def test_a_fine_tune_flies_nine_obstacles_from_its_first_step_and_names_its_parent() -> None:
    tuned = train_config(1_000_000, init_from="cd" * 32)
    assert tuned.curriculum == ((0.0, 9),) and tuned.init_from == "cd" * 32
    assert train_config(1_000_000).init_from is None
    assert tuned.model_copy(
        update={"curriculum": train_config(1).curriculum, "init_from": None}
    ) == (train_config(1_000_000))  # otherwise the recipe's settings
