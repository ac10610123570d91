"""The whole state of a training run at an update boundary: ``training-state.pt``.

Written atomically beside ``checkpoint.pt`` (:mod:`.ppo` saves both together), it holds
everything that moves a number of the updates still to come, so that :func:`.ppo.resume`
continues a stopped run bit for bit: the weights and the optimiser's moments, the torch and
numpy random streams, the return scaler, the curriculum's count, the recurrent state and the
episode starts, the current observations, the progress rows so far, and the environment itself
(its rooms, per-room random streams, maps and positions). The environment is pickled whole, so
this file is a pickle: resume only runs you made. Its arrays travel out of band, each
compressed: the 0.1 m maps of 64 rooms of up to 20 x 20 x 8 m fill 600 MB, nearly all zeros.
"""

from __future__ import annotations

import dataclasses
import pickle
import zipfile
import zlib
from pathlib import Path
from typing import Any

import torch
from pydantic import ValidationError

from seminspect.core.errors import FileFormatError
from seminspect.core.io import atomic_write_with
from seminspect.core.torch_files import check_archive, unreadable
from seminspect.core.validation import describe_validation_error
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import PolicyConfig
from seminspect.missions.learning.progress import ProgressRow
from seminspect.missions.learning.train_config import TrainConfig

#: The file name a training run saves its state under, beside ``checkpoint.pt``.
TRAINING_STATE_NAME = "training-state.pt"
STATE_FORMAT = "seminspect-rl-training-state"
#: 2: the pickled environment keeps each room's last f_t (the shaped reward's potential); a
#: version 1 environment would resume without it.
STATE_VERSION = 2
_KIND = "training state"


@dataclasses.dataclass(frozen=True)
class TrainingState:
    """A run stopped after ``updates`` updates; ``run`` is the trainer's own part."""

    policy_config: PolicyConfig
    train_config: TrainConfig
    env_config: EnvConfig
    device: str
    updates: int
    steps: int
    rows: tuple[ProgressRow, ...]
    run: dict[str, Any]

    @property
    def finished(self) -> bool:
        return self.updates >= self.train_config.updates


def save_training_state(path: str | Path, state: TrainingState) -> Path:
    """Write ``state`` atomically (protocol 4: an environment's maps may pass 4 GB)."""
    payload = {
        "format": STATE_FORMAT,
        "version": STATE_VERSION,
        "policy_config": state.policy_config.model_dump(mode="json"),
        "train_config": state.train_config.model_dump(mode="json"),
        "env_config": state.env_config.model_dump(mode="json"),
        "device": state.device,
        "updates": state.updates,
        "steps": state.steps,
        "rows": [dataclasses.asdict(row) for row in state.rows],
        "run": state.run | {"env": _packed(state.run["env"])},
    }
    return atomic_write_with(path, lambda buffer: torch.save(payload, buffer, pickle_protocol=4))


def read_training_state(path: str | Path) -> TrainingState:
    """The state :func:`save_training_state` wrote; a missing, damaged or foreign file is a
    :class:`FileFormatError` with one line."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(
            f"{source}: no saved training state to resume from (a run writes it with its "
            "first checkpoint)"
        )
    check_archive(source, _KIND, "resume from a copy or train again")
    try:
        payload = torch.load(source, map_location="cpu", weights_only=False)
    except (
        pickle.UnpicklingError,
        RuntimeError,
        EOFError,
        ValueError,
        zipfile.BadZipFile,
        AttributeError,  # AttributeError, ImportError: pickled by a version whose classes moved
        ImportError,
    ) as exc:
        raise unreadable(source, _KIND, exc) from None
    if not isinstance(payload, dict) or payload.get("format") != STATE_FORMAT:
        raise FileFormatError(f"{source}: not a {STATE_FORMAT} file")
    if payload.get("version") != STATE_VERSION:
        raise FileFormatError(
            f"{source}: training state version {payload.get('version')!r} is not supported "
            f"(supported: {STATE_VERSION})"
        )
    try:
        return TrainingState(
            policy_config=PolicyConfig.model_validate(payload["policy_config"]),
            train_config=TrainConfig.model_validate(payload["train_config"]),
            env_config=EnvConfig.model_validate(payload["env_config"]),
            device=str(payload["device"]),
            updates=int(payload["updates"]),
            steps=int(payload["steps"]),
            rows=tuple(ProgressRow(**row) for row in payload["rows"]),
            run=payload["run"] | {"env": _unpacked(payload["run"]["env"])},
        )
    except KeyError as exc:
        raise FileFormatError(f"{source}: incomplete {_KIND} (no {exc.args[0]!r})") from None
    except ValidationError as exc:
        message = describe_validation_error(exc, "configuration")
        raise FileFormatError(f"{source}: {message}") from None
    except (
        TypeError,
        ValueError,
        EOFError,
        zlib.error,
        pickle.UnpicklingError,
        AttributeError,
        ImportError,
    ) as exc:
        raise FileFormatError(f"{source}: malformed {_KIND} ({exc})") from None


def _packed(env: object) -> dict[str, Any]:
    """``env`` pickled with its (contiguous numpy) arrays out of band, each zlib-compressed."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(env, protocol=5, buffer_callback=buffers.append)
    return {"pickle": data, "buffers": [zlib.compress(b.raw(), 1) for b in buffers]}


def _unpacked(packed: dict[str, Any]) -> object:
    # bytearray: arrays over bytes would be read-only, and the env writes its maps in place
    buffers = [bytearray(zlib.decompress(b)) for b in packed["buffers"]]
    return pickle.loads(packed["pickle"], buffers=buffers)
