"""``seminspect rl train`` in pieces (--max-minutes, --resume) and ``rl show`` in the rooms a
policy was trained in."""

from __future__ import annotations

import pytest
import torch

from cli_runner import run
from seminspect.missions.learning.checkpoints import read_checkpoint, save_checkpoint
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig

#: Two updates of four rooms.
TINY = ("--steps", "256", "--envs", "4")


def test_a_run_stopped_by_its_time_limit_resumes_to_its_end(capsys, tmp_path) -> None:
    """In two pieces (bit for bit as in one: tests/missions/learning/test_ppo.py)."""
    pieces = tmp_path / "pieces"
    code, stdout, err = run(capsys, "rl", "train", *TINY, "--max-minutes", "0", "-o", str(pieces))
    assert code == 0, err
    assert "stopped at step 128 of 256 after" in stdout
    assert f"continue with: seminspect rl train --resume {pieces}" in stdout
    code, stdout, err = run(capsys, "rl", "train", "--resume", str(pieces))
    assert code == 0, err
    assert "256 steps in" in stdout
    assert read_checkpoint(pieces / "checkpoint.pt").env_config.room_size_range is not None
    with (pieces / "progress.csv").open() as log:
        assert [line.split(",")[0] for line in log] == ["update", "1", "2"]
    code, stdout, _ = run(capsys, "rl", "train", "--resume", str(pieces))
    assert code == 0 and "the run is finished (256 of 256 steps); nothing to resume" in stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--steps", "9"], "--resume continues a run with its own settings; drop --steps"),
        (["--seed", "0", "-o", "x"], "drop --seed, --out"),
        ([], "no saved training state to resume from"),
    ],
)
def test_resume_refuses_new_settings_or_a_folder_without_a_state(capsys, tmp_path, args, message):
    code, _, err = run(capsys, "rl", "train", "--resume", str(tmp_path), *args)
    assert code == 1 and message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) <= 2  # rich may wrap the one line


def test_a_new_run_needs_out(capsys) -> None:
    code, _, err = run(capsys, "rl", "train", "--steps", "9")
    assert code == 1 and "--out is needed for a new run" in err


def test_show_flies_the_rooms_of_the_policy_checkpoint(capsys, tmp_path, monkeypatch) -> None:
    import seminspect.missions.learning.env as env_module
    import seminspect.missions.learning.live as live_module

    rooms = EnvConfig(room_size=(5.0, 5.0, 3.0), target_shapes=("sphere",), episode_seconds=0.5)
    torch.manual_seed(0)
    policy = InspectionPolicy(PolicyConfig.small())
    path = save_checkpoint(tmp_path / "p.pt", policy, None, steps=0, env_config=rooms)
    seen: list[EnvConfig] = []

    class Spied(env_module.InspectionVectorEnv):
        def __init__(self, num_envs: int, config: EnvConfig, **options: object) -> None:
            seen.append(config)
            super().__init__(num_envs, config, **options)  # type: ignore[arg-type]

    monkeypatch.setattr(live_module, "InspectionVectorEnv", Spied)  # where rl show flies
    out = tmp_path / "show"
    code, _, err = run(capsys, "rl", "show", "-p", str(path), "--obstacles", "2", "-o", str(out))
    assert code == 0, err
    assert seen == [rooms.model_copy(update={"obstacles": 2})]
    assert seen[0].steps_per_episode == 5


def test_sigterm_says_how_to_continue(capsys, tmp_path, monkeypatch) -> None:
    import signal

    from seminspect.core.interrupts import Interrupted
    from seminspect.missions.learning import ppo

    def stopped(*args: object, **options: object) -> None:
        (tmp_path / "training-state.pt").write_bytes(b"")  # what train saved before it stopped
        raise Interrupted(signal.SIGTERM)

    monkeypatch.setattr(ppo, "train", stopped)
    code, _, err = run(capsys, "rl", "train", *TINY, "-o", str(tmp_path))
    assert code == 143
    assert f"stopped by SIGTERM; continue with: seminspect rl train --resume {tmp_path}" in err
