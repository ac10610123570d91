"""Training the learned detector: the CI smoke training (the loss falls, the held-out IoU is
far above chance), bit-for-bit resumption, clean stops, and the ONNX export."""

from __future__ import annotations

import csv
import math
import os
import signal

import numpy as np
import pytest

from detector_data import SMOKE_STEPS, smoke_training, write_dataset
from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.interrupts import Interrupted

torch = pytest.importorskip("torch")
onnx = pytest.importorskip("onnx")

from seminspect.perception import training  # noqa: E402 - after the torch skip
from seminspect.perception.segnet_io import (  # noqa: E402
    read_checkpoint,
    read_training_state,
    torch_probabilities,
)
from seminspect.perception.training import export_onnx, train_detector  # noqa: E402

#: Resumption and stops need no learning: the smallest network, a few steps.
TINY = {"batch": 4, "eval_every": 3, "threads": 1, "channels": (6, 8)}


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    return smoke_training(tmp_path_factory.getbasetemp())


@pytest.mark.slow  # ~10 s: the CI smoke training itself
def test_the_smoke_training_learns_the_rectangles(smoke) -> None:
    _, result = smoke
    rows = result.rows
    assert result.finished and result.steps == SMOKE_STEPS
    assert rows[-1]["loss"] < 0.5 * rows[0]["loss"]
    # chance (everything background) scores about 0.45 here: background's share, car's 0
    assert rows[-1]["miou"] > 0.8 and rows[-1]["pixel_acc"] > 0.95
    assert rows[-1]["part_miou"] > 0.3
    with (result.checkpoint.parent / "progress.csv").open() as handle:
        logged = list(csv.DictReader(handle))
    assert [int(r["step"]) for r in logged] == [50, 100, 150, 200]
    assert math.isclose(float(logged[-1]["miou"]), rows[-1]["miou"], rel_tol=1e-5)


def _weights(path) -> dict[str, torch.Tensor]:
    net, _ = read_checkpoint(path)
    return net.state_dict()


def test_a_resumed_run_ends_with_the_weights_of_an_unbroken_one(tmp_path) -> None:
    data = write_dataset(tmp_path / "data", frames=8)
    whole = train_detector(data, tmp_path / "whole", steps=8, seed=3, **TINY)
    half = train_detector(data, tmp_path / "half", steps=8, seed=3, stop_at=4, **TINY)
    assert not half.finished and half.steps == 4
    rest = train_detector(data, tmp_path / "half", steps=8, seed=3, resume=True, **TINY)
    assert rest.finished and rest.steps == 8
    a, b = _weights(whole.checkpoint), _weights(rest.checkpoint)
    assert all(torch.equal(a[name], b[name]) for name in a)
    assert (tmp_path / "whole" / "progress.csv").read_text() != ""
    assert [r["loss"] for r in whole.rows] == [r["loss"] for r in rest.rows]


def test_a_run_stops_at_its_time_limit_with_its_state_saved(tmp_path) -> None:
    data = write_dataset(tmp_path / "data", frames=4, shard_size=2)
    result = train_detector(data, tmp_path / "run", steps=50, max_minutes=0.0, **TINY)
    assert result.steps == 1 and not result.finished
    assert (tmp_path / "run" / "training-state.pt").is_file()
    more = train_detector(data, tmp_path / "run", steps=50, resume=True, stop_at=2, **TINY)
    assert more.steps == 2


def test_sigterm_stops_the_run_after_its_step_with_its_state_saved(tmp_path, monkeypatch) -> None:
    data = write_dataset(tmp_path / "data", frames=4, shard_size=2)
    step = training._Run.train_step

    def signalled(run) -> None:  # the signal arrives in the middle of step 3
        if run.step == 2:
            os.kill(os.getpid(), signal.SIGTERM)
        step(run)

    monkeypatch.setattr(training._Run, "train_step", signalled)
    with pytest.raises(Interrupted):
        train_detector(data, tmp_path / "run", steps=50, **TINY)
    assert read_training_state(tmp_path / "run" / "training-state.pt")["step"] == 3
    assert read_checkpoint(tmp_path / "run" / "checkpoint.pt")[1] == 3


def test_resuming_refuses_other_settings_or_no_state(tmp_path) -> None:
    data = write_dataset(tmp_path / "data", frames=4, shard_size=2)
    train_detector(data, tmp_path / "run", steps=4, stop_at=1, **TINY)
    with pytest.raises(InvalidInputError, match=r"\['lr'\] differ"):
        train_detector(data, tmp_path / "run", steps=4, lr=0.1, resume=True, **TINY)
    with pytest.raises(FileFormatError, match="no saved training state"):
        train_detector(data, tmp_path / "none", steps=4, resume=True, **TINY)


def test_a_damaged_checkpoint_is_one_line(tmp_path) -> None:
    data = write_dataset(tmp_path / "data", frames=4, shard_size=2)
    result = train_detector(data, tmp_path / "run", steps=1, **TINY)
    raw = bytearray(result.checkpoint.read_bytes())
    middle = len(raw) // 2
    raw[middle : middle + 8] = b"\x00" * 8
    result.checkpoint.write_bytes(bytes(raw))
    with pytest.raises(FileFormatError) as caught:
        read_checkpoint(result.checkpoint)
    assert "\n" not in str(caught.value)
    with pytest.raises(FileFormatError, match="no such file"):
        read_checkpoint(tmp_path / "missing.pt")


def test_the_export_is_a_checked_onnx_model_that_computes_what_torch_does(smoke, tmp_path) -> None:
    import onnxruntime

    _, result = smoke
    model = export_onnx(result.checkpoint, tmp_path / "model.onnx")
    loaded = onnx.load(model)
    onnx.checker.check_model(loaded)
    meta = {p.key: p.value for p in loaded.metadata_props}
    assert meta["seminspect.format"] == "seminspect.segnet"
    assert meta["parts"] == '["none", "wheel", "window"]'
    assert model.stat().st_size < 5_000_000
    images = np.random.default_rng(0).random((1, 3, 48, 64), dtype=np.float32)
    session = onnxruntime.InferenceSession(str(model), providers=["CPUExecutionProvider"])
    ours = session.run(None, {"images": images})
    theirs = torch_probabilities(read_checkpoint(result.checkpoint)[0], images)
    assert max(float(np.abs(a - b).max()) for a, b in zip(ours, theirs, strict=True)) < 1e-4
