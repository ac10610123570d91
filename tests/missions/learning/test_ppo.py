"""The recurrent PPO trainer on a toy vector env with the inspection env's observations."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from fake_vector_env import TargetReachEnv
from seminspect.missions.learning.checkpoints import read_checkpoint
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.ppo import train
from seminspect.missions.learning.progress import ProgressRow
from seminspect.missions.learning.train_config import TrainConfig

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
