"""Policy checkpoints: a round trip, and one-line errors for every broken or foreign file."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
import torch

from seminspect.core.errors import FileFormatError, SeminspectError
from seminspect.missions.learning.checkpoints import load_policy, read_checkpoint, save_checkpoint
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig


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
