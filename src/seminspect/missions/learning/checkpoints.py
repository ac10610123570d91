"""Policy checkpoints: the weights with the network, training and environment settings that
made them.

One file, written atomically by :func:`save_checkpoint`; :func:`read_checkpoint` turns any way
it can be missing, broken or made for another network into a one-line
:class:`~seminspect.core.errors.FileFormatError`. Before unpickling it checks every member's
CRC (``torch.load`` does not, so damaged weights would load as other numbers) and then the
types of the fields the file declares. Version 1 (policy v1: the shipped policy and the
ablations in ``bench/checkpoints/rl``) recorded no environment: it reads as
:meth:`EnvConfig.legacy`, the environment those were trained in.
"""

from __future__ import annotations

import dataclasses
import pickle
import zipfile
from pathlib import Path
from typing import Any

import torch
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from seminspect.core.errors import FileFormatError
from seminspect.core.io import atomic_write_with
from seminspect.core.torch_files import check_archive, unreadable
from seminspect.core.validation import describe_validation_error
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig

CHECKPOINT_FORMAT = "seminspect-rl-policy"
CHECKPOINT_VERSION = 2
#: Version 1 recorded no env config (read as :meth:`EnvConfig.legacy`).
SUPPORTED_VERSIONS = (1, 2)
#: The file name a training run saves its checkpoint under.
CHECKPOINT_NAME = "checkpoint.pt"


@dataclasses.dataclass(frozen=True)
class Checkpoint:
    """A saved policy with the configurations that produced it."""

    policy: InspectionPolicy
    policy_config: PolicyConfig
    train_config: TrainConfig | None
    steps: int
    env_config: EnvConfig  # the rooms it was trained in (and should be flown in)


class _Declared(BaseModel):
    """The payload fields beside the weights, with their types (``steps`` a real int)."""

    model_config = ConfigDict(extra="ignore")

    policy_config: dict[str, Any]
    train_config: dict[str, Any] | None = None
    env_config: dict[str, Any] | None = None  # None only in version 1
    steps: int = Field(0, ge=0, strict=True)  # strict: a bool or "many" is not a step count


def save_checkpoint(
    path: str | Path,
    policy: InspectionPolicy,
    train_config: TrainConfig | None,
    steps: int,
    env_config: EnvConfig,
) -> Path:
    """Write the policy's weights and configurations atomically."""
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": CHECKPOINT_VERSION,
        "policy_config": policy.config.model_dump(mode="json"),
        "train_config": None if train_config is None else train_config.model_dump(mode="json"),
        "env_config": env_config.model_dump(mode="json"),
        "steps": steps,
        "state_dict": policy.state_dict(),
    }
    return atomic_write_with(path, lambda buffer: torch.save(payload, buffer))


def read_checkpoint(path: str | Path) -> Checkpoint:
    """Load a checkpoint written by :func:`save_checkpoint`; any way it can be missing, broken
    or made for another network is a :class:`FileFormatError` with one line."""
    source = Path(path)
    if not source.is_file():
        reason = "is a directory" if source.is_dir() else "no such file"
        raise FileFormatError(f"{source}: {reason}, expected a policy checkpoint")
    check_archive(source, "policy checkpoint", "copy the file again or train a new one")
    try:
        payload = torch.load(source, map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError, zipfile.BadZipFile) as exc:
        raise unreadable(source, "policy checkpoint", exc) from None
    if not isinstance(payload, dict) or payload.get("format") != CHECKPOINT_FORMAT:
        raise FileFormatError(f"{source}: not a {CHECKPOINT_FORMAT} checkpoint")
    version = payload.get("version")
    if version not in SUPPORTED_VERSIONS:
        raise FileFormatError(
            f"{source}: checkpoint version {version!r} is not supported "
            f"(supported: {', '.join(map(str, SUPPORTED_VERSIONS))})"
        )
    if version >= 2 and payload.get("env_config") is None:
        raise FileFormatError(f"{source}: a version {version} checkpoint needs its env_config")
    try:
        declared = _Declared.model_validate(payload)
    except ValidationError as exc:
        raise FileFormatError(f"{source}: {describe_validation_error(exc, 'field')}") from None
    try:
        policy_config = PolicyConfig.model_validate(declared.policy_config)
        train = declared.train_config
        train_config = None if train is None else TrainConfig.model_validate(train)
        env_config = (
            EnvConfig.legacy(use_svs=policy_config.use_svs)
            if declared.env_config is None
            else EnvConfig.model_validate(declared.env_config)
        )
    except ValidationError as exc:
        message = describe_validation_error(exc, "configuration")
        raise FileFormatError(f"{source}: {message}") from None
    policy = InspectionPolicy(policy_config)
    try:
        policy.load_state_dict(payload["state_dict"])
    except (KeyError, RuntimeError, TypeError):
        raise FileFormatError(
            f"{source}: its weights do not fit its policy configuration"
        ) from None
    policy.eval()
    return Checkpoint(policy, policy_config, train_config, declared.steps, env_config)


def load_policy(path: str | Path) -> InspectionPolicy:
    """The policy of a checkpoint, in evaluation mode."""
    return read_checkpoint(path).policy
