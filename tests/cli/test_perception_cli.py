"""``seminspect perception dataset``: where it wrote and what, and one line for a bad argument."""

from __future__ import annotations

from pathlib import Path

import pytest

from cli_runner import run
from detector_data import write_dataset
from seminspect.perception.dataset import load_dataset
from seminspect.perception.learned import LearnedDetector

TINY = ("--frames", "4", "--size", "48x36", "--shard-size", "2", "--worlds", "campus:small")


def test_a_dataset_is_written_and_summed_up(capsys, tmp_path: Path) -> None:
    out = tmp_path / "data"
    code, stdout, err = run(capsys, "perception", "dataset", "--out", str(out), *TINY)
    assert code == 0, err
    assert f"dataset: {out} (2 shards)" in stdout
    assert "4 frames (campus:small 4;" in stdout and "pixels: background" in stdout
    dataset = load_dataset(out)
    assert dataset.size == (48, 36) and dataset.frames == 4
    assert "--size 48x36" in dataset.manifest["command"]
    code, stdout, err = run(capsys, "perception", "dataset", "--out", str(out), *TINY)
    assert code == 0, err  # a finished dataset: nothing to add
    code, _, err = run(capsys, "perception", "dataset", "--out", str(out), "--held-out", *TINY)
    assert code == 1 and "holds a dataset made by" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--size", "320"), "--size takes WIDTHxHEIGHT"),
        (("--frames", "0"), "frames must be at least 1"),
        (("--worlds", "nowhere"), "unknown world 'nowhere'"),
        (("--worlds", "room:0"), "holds no car, truck, building"),
    ],
)
def test_bad_arguments_are_one_line(capsys, tmp_path: Path, args, message: str) -> None:
    code, _, err = run(capsys, "perception", "dataset", "--out", str(tmp_path / "d"), *args)
    assert code == 1
    assert err.startswith("error:") and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "d").exists()


def test_train_export_and_fly_a_model_from_the_command_line(capsys, tmp_path: Path) -> None:
    data = write_dataset(tmp_path / "data", frames=8, shard_size=4)
    out = tmp_path / "train"
    code, text, _ = run(
        capsys, "perception", "train", str(data), "--out", str(out), "--steps", "6",
        "--batch", "2", "--threads", "1",
    )  # fmt: skip
    assert code == 0 and "6 of 6 steps finished" in text and "parameters" in text
    code, _, _ = run(
        capsys, "perception", "train", str(data), "--out", str(out), "--steps", "8", "--resume"
    )
    assert code != 0  # a resumed run keeps its settings
    model, checkpoint = tmp_path / "model.onnx", str(out / "checkpoint.pt")
    code, text, _ = run(capsys, "perception", "export", checkpoint, "-o", str(model))
    assert code == 0 and f"wrote {model}" in text
    assert LearnedDetector.load(model).name == "learned:model.onnx"
    code, _, err = run(capsys, "perception", "export", checkpoint, "-o", "m.pt")
    assert code != 0 and "*.onnx" in err
