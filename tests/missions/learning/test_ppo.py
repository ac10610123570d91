"""The recurrent PPO trainer on a toy vector env with the inspection env's observations."""

from __future__ import annotations

import csv
import os
import signal
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch

from fake_vector_env import TargetReachEnv
from seminspect.core.errors import InvalidInputError
from seminspect.core.interrupts import Interrupted
from seminspect.missions.learning.checkpoints import read_checkpoint
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.ppo import TrainResult, resume, train
from seminspect.missions.learning.progress import ProgressRow
from seminspect.missions.learning.train_config import TrainConfig
from seminspect.missions.learning.training_state import (
    TRAINING_STATE_NAME,
    TrainingState,
    read_training_state,
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
#: What the checkpoints record as the toy env's settings.
ROOMS = EnvConfig(obstacles=2)


def run(tmp_path: Path, updates: int, **changes: object) -> tuple[list[ProgressRow], list]:
    config = TrainConfig.model_validate(QUICK | {"total_steps": updates * 8 * 16} | changes)
    rows: list[ProgressRow] = []
    envs: list[TargetReachEnv] = []

    def make_env(num_envs: int, seed: int) -> TargetReachEnv:
        envs.append(TargetReachEnv(num_envs, seed))
        return envs[-1]

    train(make_env, PolicyConfig.small(), config, tmp_path, env_config=ROOMS, progress=rows.append)
    return rows, envs


def test_a_reward_shaped_for_another_discount_is_refused_before_training(tmp_path: Path) -> None:
    config = TrainConfig.model_validate(QUICK | {"total_steps": 128})
    shaped = EnvConfig(shaping_discount=0.99)  # PPO discounts by QUICK's 0.9
    with pytest.raises(InvalidInputError, match=r"discount 0\.99 but PPO discounts by 0\.9"):
        train(TargetReachEnv, PolicyConfig.small(), config, tmp_path, env_config=shaped)
    assert not any(tmp_path.iterdir())  # nothing written


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
    assert checkpoint.train_config == TrainConfig.model_validate(QUICK | {"total_steps": 384})
    assert checkpoint.policy_config == PolicyConfig.small()


def test_a_fine_tune_starts_from_the_weights_it_is_given(tmp_path: Path) -> None:
    """Three updates from a trained policy at a learning rate too small to move it: the
    checkpoint holds the initial weights, not the seed's fresh ones; another network is
    refused before anything is written."""
    run(tmp_path / "parent", updates=3)
    parent = read_checkpoint(tmp_path / "parent" / "checkpoint.pt").policy
    config = TrainConfig.model_validate(QUICK | {"total_steps": 3 * 128, "lr": 1e-12})
    train(TargetReachEnv, PolicyConfig.small(), config, tmp_path / "fresh", env_config=ROOMS)
    tuned = config.model_copy(update={"init_from": "ab" * 32})
    out = tmp_path / "tuned"
    train(TargetReachEnv, PolicyConfig.small(), tuned, out, env_config=ROOMS, initial=parent)
    weights = read_checkpoint(out / "checkpoint.pt")
    fresh = read_checkpoint(tmp_path / "fresh" / "checkpoint.pt").policy.state_dict()
    for name, value in parent.state_dict().items():
        torch.testing.assert_close(weights.policy.state_dict()[name], value, atol=1e-6, rtol=0)
    assert any(not torch.equal(fresh[n], v) for n, v in parent.state_dict().items())
    assert weights.train_config is not None and weights.train_config.init_from == "ab" * 32
    with pytest.raises(InvalidInputError, match="another network"):
        other = PolicyConfig.small(gru_size=0)
        train(TargetReachEnv, other, tuned, tmp_path / "other", env_config=ROOMS, initial=parent)
    assert not (tmp_path / "other" / "checkpoint.pt").exists()


def test_the_curriculum_adds_obstacles_as_training_goes(tmp_path: Path) -> None:
    rows, envs = run(tmp_path, updates=4, curriculum=((0.0, 0), (0.25, 4), (0.5, 9)))
    assert envs[0].obstacle_calls == [0, 4, 9]
    assert [row.obstacles for row in rows] == [0, 4, 9, 9]


def test_ctrl_c_leaves_a_last_checkpoint(tmp_path: Path) -> None:
    def stop_after_two(row: ProgressRow) -> None:
        if row.update == 2:
            raise KeyboardInterrupt

    config = TrainConfig.model_validate(
        QUICK | {"total_steps": 10 * 128, "checkpoint_every": 10**6}
    )
    with pytest.raises(KeyboardInterrupt):
        train(
            TargetReachEnv,
            PolicyConfig.small(),
            config,
            tmp_path,
            env_config=ROOMS,
            progress=stop_after_two,
        )
    assert read_checkpoint(tmp_path / "checkpoint.pt").steps == 256


# --- training in pieces ---------------------------------------------------------------------

PIECES = QUICK | {
    "total_steps": 3 * 128,
    "epochs": 2,
    "checkpoint_every": 10**6,
    "curriculum": ((0.5, 3),),
}
#: Columns of a progress row that measure the clock, not the training.
CLOCK = {"wall_s", "steps_per_s"}


def saved(run_dir: Path) -> TrainingState:
    return read_training_state(run_dir / TRAINING_STATE_NAME)


def assert_same(a: object, b: Any, where: str = "") -> None:
    """Equal to the bit: tensors, arrays, configs and containers of them, objects by vars."""
    if isinstance(a, torch.Tensor):
        assert isinstance(b, torch.Tensor) and torch.equal(a, b), where
    elif isinstance(a, np.ndarray):
        assert np.array_equal(a, b), where
    elif isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for key in a:
            assert_same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{where}[{k}]")
    elif isinstance(a, np.random.Generator):
        assert_same(a.bit_generator.state, b.bit_generator.state, where)
    elif hasattr(a, "__dict__") and not isinstance(a, type):
        assert_same(vars(a), vars(b), where)
    else:
        assert a == b, (where, a, b)


def assert_same_run(straight: Path, pieces: Path) -> None:
    a, b = saved(straight), saved(pieces)
    assert (a.updates, a.steps) == (b.updates, b.steps) and a.finished
    a.run.pop("wall_s"), b.run.pop("wall_s")
    assert_same(a.run, b.run)  # the env, the optimiser, the rngs, the recurrent state...
    for x, y in zip(a.rows, b.rows, strict=True):
        assert_same(
            {k: v for k, v in vars(x).items() if k not in CLOCK},
            {k: v for k, v in vars(y).items() if k not in CLOCK},
        )
    weights = read_checkpoint(straight / "checkpoint.pt").policy.state_dict()
    for key, value in read_checkpoint(pieces / "checkpoint.pt").policy.state_dict().items():
        assert torch.equal(weights[key], value), key
    with (straight / "progress.csv").open() as one, (pieces / "progress.csv").open() as two:
        rows = [list(csv.DictReader(one)), list(csv.DictReader(two))]
    assert [int(row["update"]) for row in rows[1]] == [1, 2, 3]  # continued, no repeats
    for x, y in zip(*rows, strict=True):
        assert {k: v for k, v in x.items() if k not in CLOCK} == {
            k: v for k, v in y.items() if k not in CLOCK
        }


def train_toy(out: Path, **options: object) -> TrainResult:
    config = TrainConfig.model_validate(PIECES)
    return train(TargetReachEnv, PolicyConfig.small(), config, out, env_config=ROOMS, **options)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def straight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The run in one piece."""
    out = tmp_path_factory.mktemp("straight")
    train_toy(out)
    return out


def test_a_run_in_pieces_is_the_run_that_never_stopped(tmp_path: Path, straight: Path) -> None:
    pieces = tmp_path / "pieces"
    first = train_toy(pieces, stop_after_s=0.0)  # stops at the first boundary
    assert (first.updates, first.steps, first.finished) == (1, 128, False)
    assert not saved(pieces).finished and saved(pieces).env_config == ROOMS
    second = resume(saved(pieces), pieces, stop_after_s=0.0)
    assert (second.updates, second.finished) == (2, False)
    last = resume(saved(pieces), pieces)
    assert (last.updates, last.steps, last.finished) == (3, 384, True)
    assert last.last is not None and last.last.obstacles == 3  # the curriculum went on
    assert_same_run(straight, pieces)


class SignalledEnv(TargetReachEnv):
    """Sends SIGTERM to this process in the middle of the second rollout (the count is the
    class's, so the pickled env is the toy env's state alone)."""

    stepped = 0

    def step(self, actions: np.ndarray) -> tuple:
        SignalledEnv.stepped += 1
        if SignalledEnv.stepped == 16 + 5:
            os.kill(os.getpid(), signal.SIGTERM)
        return super().step(actions)


def test_sigterm_mid_update_saves_at_the_boundary_after_it(tmp_path: Path, straight: Path) -> None:
    pieces = tmp_path / "pieces"
    SignalledEnv.stepped = 0
    with pytest.raises(Interrupted) as stop:
        train(
            SignalledEnv,
            PolicyConfig.small(),
            TrainConfig.model_validate(PIECES),
            pieces,
            env_config=ROOMS,
        )
    assert stop.value.signum == signal.SIGTERM
    assert saved(pieces).updates == 2  # the update under way ended first
    resume(saved(pieces), pieces)
    assert_same_run(straight, pieces)
