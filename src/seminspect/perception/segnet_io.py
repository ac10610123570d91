"""The files of the learned detector: checkpoints, resumable training states, and the ONNX
export :class:`~.learned.LearnedDetector` runs (torch and onnx: training-side only).

Checkpoints and states are ``torch.save`` archives written atomically and read with
``weights_only=True``; before reading, every member's CRC is checked (``torch.load`` does not,
so damaged weights would load as other numbers), as the 004 trainer's checkpoints do. The ONNX
file carries its label vocabularies in ``metadata_props`` (:data:`METADATA_KEYS`), so the
detector needs no side file.
"""

from __future__ import annotations

import json
import pickle
import tempfile
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import torch

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import atomic_write_bytes, atomic_write_with
from seminspect.core.torch_files import check_archive, unreadable
from seminspect.perception.learned import (
    INPUT_NAME,
    METADATA_KEYS,
    MODEL_FORMAT,
    MODEL_VERSION,
    OUTPUT_NAMES,
)
from seminspect.perception.segnet import Probabilities, SegNet, SegNetConfig

CHECKPOINT_FORMAT = "seminspect-segnet"
STATE_FORMAT = "seminspect-segnet-training-state"
FILE_VERSION = 1
CHECKPOINT_NAME = "checkpoint.pt"
TRAINING_STATE_NAME = "training-state.pt"
OPSET = 17


def save_checkpoint(path: Path, net: SegNet, steps: int, settings: dict[str, Any]) -> Path:
    """The network's weights, its configuration and the training settings that made them."""
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": FILE_VERSION,
        "net": net.config.to_dict(),
        "train": settings,
        "steps": steps,
        "state_dict": net.state_dict(),
    }
    return atomic_write_with(path, lambda buffer: torch.save(payload, buffer))


def read_checkpoint(path: str | Path) -> tuple[SegNet, int]:
    """The network of a checkpoint (in evaluation mode) and the steps that trained it."""
    payload = _load(Path(path), CHECKPOINT_FORMAT, "detector checkpoint")
    net = _net(payload, Path(path), "state_dict")
    return net, int(payload.get("steps", 0))


def save_training_state(path: Path, state: dict[str, Any]) -> Path:
    """A run's whole state (see :mod:`.training`), atomically."""
    payload = {"format": STATE_FORMAT, "version": FILE_VERSION} | state
    return atomic_write_with(path, lambda buffer: torch.save(payload, buffer))


def read_training_state(path: Path) -> dict[str, Any]:
    """The state :func:`save_training_state` wrote; a missing, damaged or foreign file is a
    one-line :class:`FileFormatError`."""
    if not path.is_file():
        raise FileFormatError(f"{path}: no saved training state to resume from")
    return _load(path, STATE_FORMAT, "detector training state")


def state_net(state: dict[str, Any], source: Path) -> SegNet:
    """The network of a training state, with its weights."""
    return _net(state, source, "model")


def _net(payload: dict[str, Any], source: Path, key: str) -> SegNet:
    try:
        net = SegNet(SegNetConfig.from_dict(payload["net"]))
        net.load_state_dict(payload[key])
    except (KeyError, TypeError, ValueError, RuntimeError, InvalidInputError):
        raise FileFormatError(f"{source}: its weights do not fit its network") from None
    return net.eval()


def _load(source: Path, kind: str, what: str) -> dict[str, Any]:
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file, expected a {what}")
    check_archive(source, what, "copy the file again or train again")
    try:
        payload = torch.load(source, map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError, zipfile.BadZipFile) as exc:
        raise unreadable(source, what, exc) from None
    if not isinstance(payload, dict) or payload.get("format") != kind:
        raise FileFormatError(f"{source}: not a {kind} file")
    if payload.get("version") != FILE_VERSION:
        raise FileFormatError(
            f"{source}: {what} version {payload.get('version')!r} is not supported "
            f"(supported: {FILE_VERSION})"
        )
    return payload


def export_onnx(
    checkpoint: str | Path, out: str | Path, *, input_size: tuple[int, int] | None = None
) -> Path:
    """The checkpoint's network as an ONNX model of one fixed input ``(1, 3, H, W)`` (the
    training images' size unless ``input_size`` = ``(H, W)`` says otherwise), outputs the
    probabilities of :class:`~.segnet.Probabilities`, labels in the metadata; checked with
    ``onnx.checker`` before it is written."""
    import onnx  # noqa: PLC0415 - the test extra's; only an export needs it

    net, _ = read_checkpoint(checkpoint)
    height, width = input_size or net.config.input_size
    with tempfile.TemporaryDirectory() as scratch, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the TorchScript exporter's deprecation notices
        exported = Path(scratch) / "model.onnx"
        torch.onnx.export(
            Probabilities(net).eval(),
            (torch.zeros(1, 3, height, width),),
            exported,
            dynamo=False,  # the torch.export path needs onnxscript, which is not installed
            input_names=[INPUT_NAME],
            output_names=list(OUTPUT_NAMES),
            opset_version=OPSET,
        )
        model = onnx.load(exported)
    values = (MODEL_FORMAT, str(MODEL_VERSION), *map(json.dumps, _vocabulary(net.config)))
    for key, value in zip(METADATA_KEYS, values, strict=True):
        entry = model.metadata_props.add()
        entry.key, entry.value = key, value
    model.producer_name = "seminspect"
    onnx.checker.check_model(model, full_check=True)
    return atomic_write_bytes(out, model.SerializeToString())


def _vocabulary(config: SegNetConfig) -> tuple[list[str], list[str]]:
    return list(config.classes), list(config.parts)


def torch_probabilities(net: SegNet, images: np.ndarray) -> tuple[np.ndarray, ...]:
    """The exported graph's outputs, computed by torch (for checking an export)."""
    with torch.no_grad():
        outputs = Probabilities(net).eval()(torch.from_numpy(images))
    return tuple(t.numpy() for t in outputs)
