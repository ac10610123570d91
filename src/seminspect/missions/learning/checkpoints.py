"""Policy checkpoints: the weights with the network and training settings that made them.

One file, written atomically by :func:`save_checkpoint`; :func:`read_checkpoint` turns any way
it can be missing, broken or made for another network into a one-line
:class:`~seminspect.core.errors.FileFormatError`.
"""

from __future__ import annotations

import dataclasses
import pickle
import zipfile
from pathlib import Path

import torch
from pydantic import ValidationError

from seminspect.core.errors import FileFormatError
from seminspect.core.io import atomic_write_with
from seminspect.core.validation import describe_validation_error
from seminspect.missions.learning.policy import InspectionPolicy, PolicyConfig
from seminspect.missions.learning.train_config import TrainConfig

CHECKPOINT_FORMAT = "seminspect-rl-policy"
CHECKPOINT_VERSION = 1
#: The file name a training run saves its checkpoint under.
CHECKPOINT_NAME = "checkpoint.pt"


@dataclasses.dataclass(frozen=True)
class Checkpoint:
    """A saved policy with the configurations that produced it."""

    policy: InspectionPolicy
    policy_config: PolicyConfig
    train_config: TrainConfig | None
    steps: int


def save_checkpoint(
    path: str | Path, policy: InspectionPolicy, train_config: TrainConfig | None, steps: int
) -> Path:
    """Write the policy's weights and configurations atomically."""
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": CHECKPOINT_VERSION,
        "policy_config": policy.config.model_dump(mode="json"),
        "train_config": None if train_config is None else train_config.model_dump(mode="json"),
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
    try:
        payload = torch.load(source, map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError, zipfile.BadZipFile) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{source}: not a readable policy checkpoint ({first})") from None
    if not isinstance(payload, dict) or payload.get("format") != CHECKPOINT_FORMAT:
        raise FileFormatError(f"{source}: not a {CHECKPOINT_FORMAT} checkpoint")
    if payload.get("version") != CHECKPOINT_VERSION:
        raise FileFormatError(
            f"{source}: checkpoint version {payload.get('version')!r} is not supported "
            f"(supported: {CHECKPOINT_VERSION})"
        )
    try:
        policy_config = PolicyConfig.model_validate(payload["policy_config"])
        train = payload.get("train_config")
        train_config = None if train is None else TrainConfig.model_validate(train)
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
    return Checkpoint(policy, policy_config, train_config, int(payload.get("steps", 0)))


def load_policy(path: str | Path) -> InspectionPolicy:
    """The policy of a checkpoint, in evaluation mode."""
    return read_checkpoint(path).policy
