"""The learned detector's network and what its trainer reads: shapes, parameter budget, the
dataset reader's checks, the seams, mirrored parts and loss weights."""

from __future__ import annotations

import numpy as np
import pytest

from detector_data import CLASSES, HEIGHT, PARTS, WIDTH, write_dataset
from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_json, save_npz_atomic, write_versioned_json
from seminspect.perception.dataset_format import FORMAT, MANIFEST, VERSION
from seminspect.perception.shards import iterate_shards, read_dataset_info
from seminspect.perception.training_data import (
    label_weights,
    load_data,
    mirror_parts,
    seams,
    split,
)

torch = pytest.importorskip("torch")

from seminspect.perception.segnet import (  # noqa: E402 - after the torch skip
    SegNet,
    SegNetConfig,
    parameter_count,
)

PARTS_OF_A_CITY = ("none", *(f"part-{k}" for k in range(20)))


def test_the_default_network_fits_its_budget_and_any_input_size() -> None:
    config = SegNetConfig(tuple(CLASSES), PARTS_OF_A_CITY, (240, 320))
    net = SegNet(config).eval()
    assert 300_000 < parameter_count(net) < 1_000_000
    with torch.no_grad():
        classes, parts, edges = net(torch.rand(2, 3, 50, 70))  # not a multiple of 16
    assert classes.shape == (2, 4, 50, 70)
    assert parts.shape == (2, len(PARTS_OF_A_CITY), 50, 70)
    assert edges.shape == (2, 1, 50, 70)
    assert SegNetConfig.from_dict(config.to_dict()) == config


def test_a_network_config_refuses_what_cannot_be_built() -> None:
    with pytest.raises(InvalidInputError, match="stage widths"):
        SegNetConfig(tuple(CLASSES), ("none",), (48, 64), channels=(2, 4))
    with pytest.raises(InvalidInputError, match="background"):
        SegNetConfig(("background",), ("none",), (48, 64))


def test_the_reader_returns_the_shards_of_a_dataset(tmp_path) -> None:
    root = write_dataset(tmp_path / "data", frames=10, shard_size=4)
    info = read_dataset_info(root)
    assert info.shape == (HEIGHT, WIDTH) and info.parts == tuple(PARTS)
    sizes = [len(shard) for shard in iterate_shards(info)]
    assert sizes == [4, 4, 2]
    data = load_data(root, 0.25)
    assert len(data.train) == 8 and list(data.val) == [8, 9]  # the last shard is held out
    assert data.edges.any()  # the touching cars meet somewhere


def _rewrite_manifest(root, **changes) -> None:
    doc = read_json(root / MANIFEST)
    payload = {k: v for k, v in doc.items() if k not in {"format", "version"}} | changes
    write_versioned_json(root / MANIFEST, FORMAT, VERSION, payload)


def test_the_reader_refuses_foreign_labels_in_one_line(tmp_path) -> None:
    root = write_dataset(tmp_path / "data", frames=4)
    _rewrite_manifest(root, classes=["background", "car"])
    with pytest.raises(FileFormatError, match="'classes' must be") as caught:
        read_dataset_info(root)
    assert "\n" not in str(caught.value)
    _rewrite_manifest(root, classes=CLASSES, parts=["wheel"])
    with pytest.raises(FileFormatError, match="'none' first"):
        read_dataset_info(root)


def test_the_reader_refuses_a_shard_of_another_size(tmp_path) -> None:
    root = write_dataset(tmp_path / "data", frames=4)
    with np.load(root / "frames-00000.npz") as data:
        arrays = {name: data[name] for name in data.files}
    arrays["class_id"] = arrays["class_id"][:, :-1]
    save_npz_atomic(root / "frames-00000.npz", **arrays)
    with pytest.raises(FileFormatError, match=r"class_id is uint8 \[4, 47, 64\], expected"):
        list(iterate_shards(root))


def test_a_missing_shard_is_refused_before_training(tmp_path) -> None:
    root = write_dataset(tmp_path / "data", frames=8)
    (root / "frames-00001.npz").unlink()
    with pytest.raises(FileFormatError, match="shards missing"):
        read_dataset_info(root)


def test_seams_mark_where_two_objects_touch_and_nowhere_else() -> None:
    instance = np.zeros((1, 6, 8), np.uint16)
    instance[0, 1:5, 1:4], instance[0, 1:5, 4:7] = 1, 2
    found = seams(instance)[0]
    assert found[1:5, 3:5].all() and found.sum() == 8


def test_mirrored_parts_swap_left_and_right() -> None:
    parts = ("none", "front-left-door", "front-right-door", "left-mirror", "wheel", "leftover")
    assert mirror_parts(parts).tolist() == [0, 2, 1, 3, 4, 5]  # no right-mirror: unchanged


def test_rare_labels_weigh_more_and_unseen_ones_weigh_the_most() -> None:
    labels = np.array([0] * 90 + [1] * 10, np.uint8)
    weights = label_weights(labels, 3)
    assert weights[1] > weights[0] and weights[2] == 10.0
    assert np.isclose(weights[:2].mean(), 1.0)


def test_one_shard_is_split_by_frames() -> None:
    train, val = split([10], 0.2)
    assert list(val) == [8, 9] and len(train) == 8
    assert len(split([3, 3], 0.0)[1]) == 0
