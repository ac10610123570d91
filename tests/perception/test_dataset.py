"""The detector dataset: labels as a direct render gives them, in the dataset's own label space;
the same bytes from the same arguments, after an interruption too; held-out seeds apart."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_versioned_json
from seminspect.perception.dataset import (
    CLASSES,
    FORMAT,
    HELD_OUT_APPEARANCES,
    MIN_TARGET_SHARE,
    TRAINING_APPEARANCES,
    VERSION,
    DatasetSpec,
    build_dataset,
    dataset_statistics,
    load_dataset,
    parse_worlds,
)
from seminspect.perception.dataset_format import SHARD_ARRAYS
from seminspect.sensors import render
from seminspect.sensors.appearance import Appearance
from seminspect.worlds import open_world

#: Six frames of 80 x 60 px in two shards, over the default worlds.
SPEC = DatasetSpec(frames=6, width=80, height=60, shard_size=3, seed=1)


def _files(directory: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(directory.iterdir())}


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("dataset")
    build_dataset(out, SPEC)
    return out


def test_the_directory_holds_the_declared_shards_and_label_space(built: Path) -> None:
    manifest = read_versioned_json(built / "dataset.json", FORMAT, [VERSION])
    assert manifest["classes"] == list(CLASSES) == ["background", "car", "truck", "building"]
    parts = manifest["parts"]
    assert parts[0] == "none" and parts[1:] == sorted(parts[1:])
    assert {"wall", "front-left-wheel", "hood"} <= set(parts)
    assert manifest["image_size"] == [80, 60] and manifest["frames"] == 6
    assert manifest["arguments"] == SPEC.arguments()
    assert sorted(p.name for p in built.iterdir()) == [
        "dataset.json", "frames-00000.npz", "frames-00001.npz",
    ]  # fmt: skip
    dataset = load_dataset(built)
    for shard, record in zip(dataset.iter_shards(), manifest["shards"], strict=True):
        for name, dtype in SHARD_ARRAYS.items():
            assert shard[name].dtype == dtype and len(shard[name]) == 3, name
        assert shard["rgb"].shape == (3, 60, 80, 3) and shard["depth"].shape == (3, 60, 80)
        assert shard["appearance_seed"].tolist() == record["appearance_seeds"]
        assert set(shard["world_seed"].tolist()) == {record["world_seed"]}
        assert shard["class_id"].max() < len(CLASSES) and shard["part_id"].max() < len(parts)
        assert not shard["part_id"][shard["class_id"] == 0].any()  # parts only on targets
        assert not shard["instance"][shard["class_id"] == 0].any()
        assert np.isinf(shard["depth"]).any()  # the sky is kept as inf


def test_labels_and_colours_agree_with_a_direct_render(built: Path) -> None:
    dataset = load_dataset(built)
    parts = dataset.parts
    for frame in dataset.iter_frames():
        name, _, scenario = frame.world.partition(":")
        world = open_world(name, scenario or None, seed=frame.world_seed)
        ideal = render(world, SPEC.camera, frame.position, frame.orientation,
                       appearance=Appearance.draw(world, frame.appearance_seed))  # fmt: skip
        names = np.array(world.class_names, dtype=object)[ideal.class_id]
        target = np.isin(names, CLASSES[1:])
        classes = np.where(target, names, "background")
        assert np.array_equal(np.array(CLASSES, dtype=object)[frame.class_id], classes)
        part_names = np.array(world.part_names, dtype=object)[ideal.part_id]
        expected = np.where(target & (part_names != ""), part_names, "none")
        assert np.array_equal(np.array(parts, dtype=object)[frame.part_id], expected)
        assert np.array_equal(frame.depth, ideal.depth.astype(np.float16))
        # the same objects, renumbered
        world_ids, dataset_ids = ideal.instance[target].tolist(), frame.instance[target].tolist()
        pairs = set(zip(world_ids, dataset_ids, strict=True))
        assert len(pairs) == len({a for a, _ in pairs}) == len({b for _, b in pairs})
        assert {b for _, b in pairs} == set(range(1, len(pairs) + 1))
        # sensor noise: a few levels off the ideal image, everywhere
        assert ideal.rgb is not None
        off = np.abs(frame.rgb.astype(int) - ideal.rgb.astype(int))
        assert 1.5 < off.mean() < 6 and off.max() < 40


def test_frames_that_look_at_a_target_show_it(built: Path) -> None:
    shards = list(load_dataset(built).iter_shards())
    target = np.concatenate([s["target"] for s in shards])
    instance_share = np.concatenate([(s["class_id"] > 0).mean(axis=(1, 2)) for s in shards])
    assert (target > 0).sum() >= 3
    assert np.all(instance_share[target > 0] >= MIN_TARGET_SHARE)


def test_statistics_count_every_pixel_and_frame(built: Path) -> None:
    stats = dataset_statistics(built)
    assert stats.frames == 6 and stats.pixels == 6 * 80 * 60
    assert sum(stats.class_pixels.values()) == stats.pixels == sum(stats.part_pixels.values())
    assert stats.frames_per_world == {"city:small": 2, "city:medium": 2, "campus:small": 2}
    assert stats.class_pixels["car"] > 0 and "pixels: background" in stats.summary()


def test_the_same_arguments_give_the_same_bytes(built: Path, tmp_path: Path) -> None:
    build_dataset(tmp_path, SPEC)
    assert _files(tmp_path) == _files(built)


def test_an_interrupted_run_finishes_with_the_same_bytes(built: Path, tmp_path: Path) -> None:
    def stop_in_second_shard(done: int, total: int) -> None:
        if done == 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        build_dataset(tmp_path, SPEC, on_progress=stop_in_second_shard)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dataset.json", "frames-00000.npz"]
    with pytest.raises(FileFormatError, match="1 of 2 shards missing"):
        load_dataset(tmp_path)
    reports: list[tuple[int, int]] = []
    build_dataset(tmp_path, SPEC, on_progress=lambda done, total: reports.append((done, total)))
    assert reports[0] == (3, 6) and reports[-1] == (6, 6)  # the first shard was kept
    assert _files(tmp_path) == _files(built)
    (tmp_path / "frames-00001.npz").unlink()
    build_dataset(tmp_path, SPEC)
    assert _files(tmp_path) == _files(built)


def test_a_directory_of_other_arguments_or_other_files_is_refused(
    built: Path, tmp_path: Path
) -> None:
    before = _files(built)
    with pytest.raises(InvalidInputError, match="holds a dataset made by 'seminspect perception"):
        build_dataset(built, DatasetSpec(frames=7, width=80, height=60, shard_size=3, seed=1))
    assert _files(built) == before
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(InvalidInputError, match="not empty"):
        build_dataset(tmp_path, SPEC)


def test_held_out_seeds_are_apart_from_training_and_evaluation(tmp_path: Path) -> None:
    held_out = DatasetSpec(worlds=(("campus", "small"),), frames=2, width=40, height=30,
                           held_out=True)  # fmt: skip
    big = DatasetSpec(frames=100_000, shard_size=64)
    training_worlds = {big.world_seed(k) for k in range(big.shards)}
    held_worlds = {held_out.world_seed(k) for k in range(big.shards)}
    assert min(training_worlds) == 10_000 and max(training_worlds) < 20_000 <= min(held_worlds)
    assert not training_worlds & set(range(60))
    build_dataset(tmp_path, held_out)
    shard = load_dataset(tmp_path).load_shard(0)
    assert np.all(shard["world_seed"] >= 20_000)
    low, high = HELD_OUT_APPEARANCES
    assert np.all((shard["appearance_seed"] >= low) & (shard["appearance_seed"] < high))
    seeds = [s for k in range(big.shards) for s in big.appearance_seeds(k)]
    assert all(TRAINING_APPEARANCES[0] <= s < TRAINING_APPEARANCES[1] for s in seeds)


@pytest.mark.parametrize(
    "kwargs", [{"frames": 0}, {"shard_size": 0}, {"width": 0}, {"worlds": ()}, {"seed": -1}]
)
def test_bad_arguments_are_refused(kwargs: dict) -> None:
    with pytest.raises(InvalidInputError):
        DatasetSpec(**kwargs)


def test_worlds_are_read_as_name_and_scenario() -> None:
    assert parse_worlds("city:small, campus") == (("city", "small"), ("campus", None))
    with pytest.raises(InvalidInputError):
        parse_worlds("city,,campus")
