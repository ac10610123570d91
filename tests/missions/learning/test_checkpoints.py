"""Policy checkpoints: a round trip, and one-line errors for every broken or foreign file."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
import torch

from seminspect.core.errors import FileFormatError, SeminspectError
from seminspect.missions.learning.agent import shipped_policy_path
from seminspect.missions.learning.checkpoints import (
    CHECKPOINT_VERSION,
    load_policy,
    read_checkpoint,
    save_checkpoint,
)
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig

ROOMS = EnvConfig(obstacles=4, target_shapes=("box", "sphere"))


def small_policy(seed: int = 0, **changes: object) -> InspectionPolicy:
    torch.manual_seed(seed)
    return InspectionPolicy(PolicyConfig.small(**changes))


def test_checkpoint_round_trip(tmp_path: Path) -> None:
    policy = small_policy(gru_size=0, use_svs=False)
    path = save_checkpoint(
        tmp_path / "p.pt", policy, TrainConfig(seed=7), steps=1234, env_config=ROOMS
    )
    loaded = load_policy(path)
    assert loaded.config == policy.config
    assert not loaded.training
    for key, value in policy.state_dict().items():
        torch.testing.assert_close(loaded.state_dict()[key], value)
    checkpoint = read_checkpoint(path)
    assert checkpoint.train_config is not None
    assert checkpoint.steps == 1234 and checkpoint.train_config.seed == 7
    assert checkpoint.env_config == ROOMS
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
    good = save_checkpoint(tmp_path / "good.pt", small_policy(), None, steps=0, env_config=ROOMS)
    truncated = tmp_path / "truncated.pt"
    truncated.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(FileFormatError) as caught:
        load_policy(truncated)
    assert "\n" not in str(caught.value)


def forged(tmp_path: Path, **changes: object) -> Path:
    """A checkpoint whose payload fields are replaced by ``changes``."""
    path = save_checkpoint(tmp_path / "good.pt", small_policy(), None, steps=0, env_config=ROOMS)
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


# Damaged after they were written, or declaring fields of the wrong type: one line naming the
# file, never other weights or an internal error.
def test_damaged_weights_are_refused_by_their_crc(tmp_path: Path) -> None:
    policy = small_policy()
    path = save_checkpoint(
        tmp_path / "policy.pt", policy, TrainConfig(), steps=10, env_config=ROOMS
    )
    weights = max(policy.state_dict().values(), key=lambda t: t.numel())
    data = bytearray(path.read_bytes())
    start = data.find(weights.numpy().tobytes())
    assert start > 0  # the tensor's bytes lie stored, uncompressed, in the archive
    data[start + 8 : start + 16] = bytes(b ^ 0xFF for b in data[start + 8 : start + 16])
    path.write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match="damaged policy checkpoint") as caught:
        read_checkpoint(path)
    message = str(caught.value)
    assert str(path) in message and "CRC" in message and "\n" not in message


def test_damaged_shipped_policy_is_refused(tmp_path: Path) -> None:
    data = bytearray(Path(shipped_policy_path()).read_bytes())
    data[-len(data) // 3] ^= 0x01  # one bit, deep inside a weight tensor
    damaged = tmp_path / "policy.pt"
    damaged.write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match="fails its CRC check"):
        read_checkpoint(damaged)


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"steps": "many"}, "invalid field steps: Input should be a valid integer"),
        ({"steps": True}, "invalid field steps: Input should be a valid integer"),
        ({"steps": -5}, "invalid field steps: Input should be greater than or equal to 0"),
        ({"policy_config": "small"}, "invalid field policy_config"),
        ({"train_config": [1, 2]}, "invalid field train_config"),
        ({"train_config": TrainConfig().model_dump() | {"seed": True}}, "configuration seed"),
    ],
)
def test_declared_fields_of_the_wrong_type_are_refused(
    tmp_path: Path, changes: dict[str, object], expected: str
) -> None:
    path = forged(tmp_path, **changes)
    with pytest.raises(FileFormatError, match=expected) as caught:
        read_checkpoint(path)
    assert str(caught.value).startswith(f"{path}: ")


def test_a_checkpoint_without_steps_still_reads_as_zero_steps(tmp_path: Path) -> None:
    path = save_checkpoint(
        tmp_path / "policy.pt", small_policy(), TrainConfig(), steps=10, env_config=ROOMS
    )
    assert read_checkpoint(path).steps == 10
    payload = torch.load(path, weights_only=True)
    del payload["steps"]
    torch.save(payload, path)
    assert read_checkpoint(path).steps == 0


@pytest.mark.parametrize("use_svs", [True, False])
def test_a_version_1_checkpoint_reads_as_the_legacy_environment(tmp_path, use_svs) -> None:
    torch.manual_seed(0)
    policy = InspectionPolicy(PolicyConfig.small(use_svs=use_svs))
    path = save_checkpoint(tmp_path / "v2.pt", policy, None, steps=0, env_config=ROOMS)
    payload = torch.load(path, weights_only=True) | {"version": 1}
    del payload["env_config"]  # version 1 had none
    torch.save(payload, path)
    assert read_checkpoint(path).env_config == EnvConfig.legacy(use_svs=use_svs)


def test_a_version_2_checkpoint_without_its_environment_is_refused(tmp_path: Path) -> None:
    assert CHECKPOINT_VERSION == 2
    with pytest.raises(FileFormatError, match="needs its env_config"):
        read_checkpoint(forged(tmp_path, env_config=None))
    with pytest.raises(FileFormatError, match="configuration obstacles"):
        read_checkpoint(forged(tmp_path, env_config={"obstacles": -1}))


def test_the_shipped_and_bench_checkpoints_are_policy_v1_in_the_legacy_rooms() -> None:
    assert read_checkpoint(shipped_policy_path()).env_config == EnvConfig.legacy()
    bench = Path(__file__).parents[3] / "bench" / "checkpoints" / "rl"
    no_svs = read_checkpoint(bench / "no-svs.pt")
    assert no_svs.env_config == EnvConfig.legacy(use_svs=False)
    assert read_checkpoint(bench / "no-gru.pt").policy_config.gru_size == 0
