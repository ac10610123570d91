"""A run's saved training state: the environment in it continues bit for bit, and a missing,
damaged or foreign state file is one readable line."""

from __future__ import annotations

import dataclasses
import gc
import pickle
from pathlib import Path

import numpy as np
import pytest
import torch

from seminspect.core.errors import FileFormatError
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig
from seminspect.missions.learning.training_state import (
    TrainingState,
    read_training_state,
    save_training_state,
)

SMALL = EnvConfig(
    room_size=(5.0, 5.0, 3.0),
    room_size_range=((4.0, 6.0), (4.0, 6.0), (2.0, 3.0)),
    target_shapes=("cylinder", "box"),
    obstacles=3,
    episode_seconds=1.0,  # 10 steps: the pickled env restarts rooms too
)


def steps(env: InspectionVectorEnv, actions: list[np.ndarray]) -> list[tuple]:
    return [env.step(action)[:4] for action in actions]


@pytest.mark.parametrize("config", [SMALL, EnvConfig.legacy(room_size=(5.0, 5.0, 3.0))])
def test_a_pickled_environment_steps_on_as_the_original(config: EnvConfig) -> None:
    env = InspectionVectorEnv(3, config, seed=5)
    env.reset(seed=5)
    actions = list(np.random.default_rng(0).uniform(-1, 1, (25, 3, 4)))
    steps(env, actions[:7])
    copy = pickle.loads(pickle.dumps(env))
    expected, shapes = steps(env, actions[7:]), [room.shape for room in env.rooms]
    del env  # a resumed run has no original: its Embree scene must not be what the copy uses
    gc.collect()
    for (a_obs, *a_rest), (b_obs, *b_rest) in zip(expected, steps(copy, actions[7:]), strict=True):
        assert all(np.array_equal(a_obs[key], b_obs[key]) for key in a_obs)
        assert all(np.array_equal(a, b) for a, b in zip(a_rest, b_rest, strict=True))
    assert [room.shape for room in copy.rooms] == shapes


def a_state() -> TrainingState:
    return TrainingState(
        PolicyConfig.small(), TrainConfig(), EnvConfig(), "cpu", 3, 6144, (), {"env": [1, 2]}
    )


def test_a_state_reads_back_with_its_settings(tmp_path: Path) -> None:
    path = save_training_state(tmp_path / "state.pt", a_state())
    state = read_training_state(path)
    assert (state.updates, state.steps, state.device) == (3, 6144, "cpu")
    assert state.train_config == TrainConfig() and state.env_config == EnvConfig()
    assert state.run == {"env": [1, 2]} and not state.finished


def test_the_environment_is_saved_compressed_and_comes_back_writable(tmp_path: Path) -> None:
    env = InspectionVectorEnv(2, EnvConfig(room_size=(20.0, 20.0, 8.0)), seed=1)
    env.reset(seed=1)
    maps = sum(v.nbytes for v in vars(env).values() if isinstance(v, np.ndarray))
    state = a_state()
    path = save_training_state(tmp_path / "state.pt", dataclasses.replace(state, run={"env": env}))
    assert maps > 15e6 and path.stat().st_size < maps / 20  # mostly zeros
    copy = read_training_state(path).run["env"]
    copy.step(np.zeros((2, 4)))  # its maps are written in place
    env.step(np.zeros((2, 4)))
    assert np.array_equal(copy._occupancy, env._occupancy)


def rewritten(tmp_path: Path, **changes: object) -> Path:
    path = save_training_state(tmp_path / "state.pt", a_state())
    payload = torch.load(path, weights_only=False) | changes
    torch.save(payload, path)
    return path


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: d / "absent.pt", "no saved training state to resume from"),
        (lambda d: d, "no saved training state to resume from"),
        (lambda d: (d / "x.pt").write_bytes(b"garbage") and d / "x.pt", "not a readable training"),
        (lambda d: rewritten(d, format="other"), "not a seminspect-rl-training-state file"),
        (lambda d: rewritten(d, version=7), "version 7 is not supported"),
        (lambda d: rewritten(d, train_config={"num_envs": "many"}), "configuration num_envs"),
        (lambda d: rewritten(d, rows=[{"update": 1}]), "malformed training state"),
    ],
)
def test_a_bad_state_file_is_one_line(tmp_path: Path, make, message: str) -> None:
    path = make(tmp_path)
    with pytest.raises(FileFormatError, match=message) as caught:
        read_training_state(path)
    assert "\n" not in str(caught.value) and str(path) in str(caught.value)


def test_an_incomplete_or_truncated_state_is_one_line(tmp_path: Path) -> None:
    path = save_training_state(tmp_path / "state.pt", a_state())
    payload = torch.load(path, weights_only=False)
    del payload["run"]
    torch.save(payload, path)
    with pytest.raises(FileFormatError, match="incomplete training state \\(no 'run'\\)"):
        read_training_state(path)
    good = save_training_state(tmp_path / "good.pt", a_state())
    cut = tmp_path / "cut.pt"
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(FileFormatError, match="not a readable training state"):
        read_training_state(cut)
