"""The recurrent PPO trainer on a toy vector env with the inspection env's observations."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest
import torch
from pydantic import ValidationError

from fake_vector_env import TargetReachEnv
from seminspect.core.errors import FileFormatError, SeminspectError
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig
from seminspect.missions.learning.ppo import (
    ProgressRow,
    Rollout,
    TrainConfig,
    _final_observations,
    advantages_gae,
    load_policy,
    read_checkpoint,
    save_checkpoint,
    train,
)

#: A run on the toy task: 8 envs, 16 steps a rollout, short horizon so that credit is quick.
QUICK = {
    "num_envs": 8,
    "rollout_steps": 16,
    "epochs": 4,
    "minibatches": 2,
    "lr": 3e-3,
    "gamma": 0.9,
    "gae_lambda": 0.9,
    "curriculum": (),
}


def run(tmp_path: Path, updates: int, **changes: object) -> tuple[list[ProgressRow], list]:
    config = TrainConfig(**(QUICK | {"total_steps": updates * 8 * 16} | changes))
    rows: list[ProgressRow] = []
    envs: list[TargetReachEnv] = []

    def make_env(num_envs: int, seed: int) -> TargetReachEnv:
        envs.append(TargetReachEnv(num_envs, seed))
        return envs[-1]

    train(make_env, PolicyConfig.small(), config, tmp_path, progress=rows.append)
    return rows, envs


def test_training_raises_the_return(tmp_path: Path) -> None:
    rows, envs = run(tmp_path, updates=20)
    first = np.mean([row.mean_return for row in rows[:5]])
    last = np.mean([row.mean_return for row in rows[-5:]])
    assert last > first + 0.3, (first, last)
    assert np.mean([row.crash_pct for row in rows[-5:]]) < rows[0].crash_pct
    assert envs[0].closed


def test_same_seed_same_run_other_seed_other_run(tmp_path: Path) -> None:
    def first_losses(seed: int, folder: str) -> tuple[float, ...]:
        rows, _ = run(tmp_path / folder, updates=1, seed=seed)
        return (rows[0].policy_loss, rows[0].value_loss, rows[0].approx_kl, rows[0].mean_return)

    assert first_losses(0, "a") == first_losses(0, "b")
    assert first_losses(0, "a") != first_losses(1, "c")


def test_logs_and_checkpoint_are_written(tmp_path: Path) -> None:
    rows, _ = run(tmp_path, updates=3)
    with (tmp_path / "progress.csv").open() as handle:
        logged = list(csv.DictReader(handle))
    assert [int(row["steps"]) for row in logged] == [128, 256, 384]
    assert {"mean_return", "coverage_pct", "crash_pct", "policy_loss", "entropy"} <= set(logged[0])
    assert float(logged[-1]["value_loss"]) == pytest.approx(rows[-1].value_loss, rel=1e-5)
    pytest.importorskip("tensorboardX")
    assert list(tmp_path.glob("events.out.tfevents.*"))
    checkpoint = read_checkpoint(tmp_path / "checkpoint.pt")
    assert checkpoint.steps == 384
    assert checkpoint.train_config == TrainConfig(**(QUICK | {"total_steps": 384}))
    assert checkpoint.policy_config == PolicyConfig.small()


def test_the_curriculum_adds_obstacles_as_training_goes(tmp_path: Path) -> None:
    rows, envs = run(tmp_path, updates=4, curriculum=((0.0, 0), (0.25, 4), (0.5, 9)))
    assert envs[0].obstacle_calls == [0, 4, 9]
    assert [row.obstacles for row in rows] == [0, 4, 9, 9]


def test_ctrl_c_leaves_a_last_checkpoint(tmp_path: Path) -> None:
    def stop_after_two(row: ProgressRow) -> None:
        if row.update == 2:
            raise KeyboardInterrupt

    config = TrainConfig(**(QUICK | {"total_steps": 10 * 128, "checkpoint_every": 10**6}))
    with pytest.raises(KeyboardInterrupt):
        train(TargetReachEnv, PolicyConfig.small(), config, tmp_path, progress=stop_after_two)
    assert read_checkpoint(tmp_path / "checkpoint.pt").steps == 256


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


def test_train_config_is_validated() -> None:
    with pytest.raises(ValidationError, match="multiple of minibatches"):
        TrainConfig(num_envs=6, minibatches=4)
    with pytest.raises(ValidationError, match="fractions must rise"):
        TrainConfig(curriculum=((0.5, 4), (0.2, 9)))
    with pytest.raises(ValidationError, match="fractions must rise"):
        TrainConfig(curriculum=((1.0, 4),))
    config = TrainConfig(curriculum=((0.1, 4), (0.5, 9)))
    assert [config.obstacles_at(f) for f in (0.0, 0.1, 0.49, 0.9)] == [None, 4, 4, 9]


def small_policy(seed: int = 0, **changes: object) -> InspectionPolicy:
    torch.manual_seed(seed)
    return InspectionPolicy(PolicyConfig.small(**changes))


def test_checkpoint_round_trip(tmp_path: Path) -> None:
    policy = small_policy(gru_size=0, use_svs=False)
    path = save_checkpoint(tmp_path / "p.pt", policy, TrainConfig(seed=7), steps=1234)
    loaded = load_policy(path)
    assert loaded.config == policy.config
    assert not loaded.training
    for key, value in policy.state_dict().items():
        torch.testing.assert_close(loaded.state_dict()[key], value)
    checkpoint = read_checkpoint(path)
    assert checkpoint.steps == 1234 and checkpoint.train_config.seed == 7
    assert not list(tmp_path.glob(".p.pt.*"))  # no temporary left behind


def test_broken_checkpoints_are_one_line_errors(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="no such file"):
        load_policy(tmp_path / "absent.pt")
    with pytest.raises(FileFormatError, match="is a directory"):
        load_policy(tmp_path)
    garbage = tmp_path / "garbage.pt"
    garbage.write_bytes(b"not a checkpoint at all")
    with pytest.raises(FileFormatError, match="not a readable policy checkpoint"):
        load_policy(garbage)
    good = save_checkpoint(tmp_path / "good.pt", small_policy(), None, steps=0)
    truncated = tmp_path / "truncated.pt"
    truncated.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(FileFormatError) as caught:
        load_policy(truncated)
    assert "\n" not in str(caught.value)


def forged(tmp_path: Path, **changes: object) -> Path:
    """A checkpoint whose payload fields are replaced by ``changes``."""
    path = save_checkpoint(tmp_path / "good.pt", small_policy(), None, steps=0)
    payload = torch.load(path, weights_only=True) | changes
    buffer = io.BytesIO()
    torch.save(payload, buffer)
    target = tmp_path / "forged.pt"
    target.write_bytes(buffer.getvalue())
    return target


def test_checkpoints_of_other_kinds_or_networks_are_refused(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="not a seminspect-rl-policy"):
        load_policy(forged(tmp_path, format="something-else"))
    with pytest.raises(FileFormatError, match="version 99 is not supported"):
        load_policy(forged(tmp_path, version=99))
    other = PolicyConfig.small(gru_size=64).model_dump(mode="json")
    with pytest.raises(FileFormatError, match="do not fit"):
        load_policy(forged(tmp_path, policy_config=other))
    broken = PolicyConfig.small().model_dump(mode="json") | {"gru_size": -3}
    with pytest.raises(SeminspectError, match="gru_size"):
        load_policy(forged(tmp_path, policy_config=broken))


def test_final_observations_in_either_layout() -> None:
    env = TargetReachEnv(3, seed=0)
    obs, _ = env.reset(seed=0)
    rows = np.array([False, True, True])
    stacked = _final_observations({"final_obs": obs}, rows)
    per_env = {key: np.empty(3, dtype=object) for key in obs}
    for key, value in obs.items():
        for row in range(3):
            per_env[key][row] = value[row] if rows[row] else None
    from_objects = _final_observations({"final_obs": per_env}, rows)
    for key in obs:
        np.testing.assert_array_equal(stacked[key], obs[key][1:])
        np.testing.assert_array_equal(from_objects[key], obs[key][1:])
