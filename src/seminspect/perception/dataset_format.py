"""Reading a detector dataset (:mod:`seminspect.perception.dataset`): its ``dataset.json``, its
shards one at a time or frame by frame for a trainer, and the pixel counts that show what a
network would learn from it."""

from __future__ import annotations

import io
import zipfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_versioned_json

FORMAT = "seminspect.detector-dataset"
VERSION = 1
MANIFEST = "dataset.json"

#: The arrays of a shard and their types: images ``(n, H, W[, 3])`` (``rgb`` with sensor noise;
#: ``instance`` the targets renumbered 1..k per frame; ``depth`` in m, inf where nothing is in
#: range), then per frame its camera pose, the target it looks at (the world's instance id; 0
#: for a random view), its world (index into ``dataset.json``'s ``worlds``), that world's seed
#: and the appearance seed.
SHARD_ARRAYS: dict[str, type] = {
    "rgb": np.uint8,
    "class_id": np.uint8,
    "part_id": np.uint8,
    "instance": np.uint16,
    "depth": np.float16,
    "position": np.float64,
    "orientation": np.float64,
    "target": np.int32,
    "world": np.uint8,
    "world_seed": np.int64,
    "appearance_seed": np.int64,
}


def shard_name(shard: int) -> str:
    return f"frames-{shard:05d}.npz"


def npz_bytes(arrays: dict[str, np.ndarray]) -> bytes:
    """The compressed ``.npz`` of ``np.savez_compressed``, with every member's time fixed:
    ``savez_compressed`` stamps the current time, so two files of equal arrays would differ."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, array in arrays.items():
            member = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            member.compress_type = zipfile.ZIP_DEFLATED
            with archive.open(member, "w", force_zip64=True) as handle:
                np.lib.format.write_array(handle, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


@dataclass(frozen=True)
class DatasetFrame:
    """One frame of a dataset, as a trainer reads it (the arrays of :data:`SHARD_ARRAYS`)."""

    rgb: NDArray[np.uint8]
    class_id: NDArray[np.uint8]
    part_id: NDArray[np.uint8]
    instance: NDArray[np.uint16]
    depth: NDArray[np.float16]
    position: NDArray[np.float64]
    orientation: NDArray[np.float64]
    target: int
    world: str
    world_seed: int
    appearance_seed: int


@dataclass(frozen=True)
class Dataset:
    """A dataset directory and its ``dataset.json``."""

    path: Path
    manifest: dict[str, Any]

    @property
    def classes(self) -> list[str]:
        return list(self.manifest["classes"])

    @property
    def parts(self) -> list[str]:
        return list(self.manifest["parts"])

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` of every frame."""
        width, height = self.manifest["image_size"]
        return int(width), int(height)

    @property
    def frames(self) -> int:
        return int(self.manifest["frames"])

    @property
    def worlds(self) -> list[str]:
        return list(self.manifest["worlds"])

    @property
    def shards(self) -> int:
        return len(self.manifest["shards"])

    def shard_path(self, shard: int) -> Path:
        return self.path / self.manifest["shards"][shard]["file"]

    def missing_shards(self) -> list[int]:
        """Shards not written yet (an interrupted run: rerun its command to finish)."""
        return [k for k in range(self.shards) if not self.shard_path(k).is_file()]

    def load_shard(
        self, shard: int, names: Iterable[str] = tuple(SHARD_ARRAYS)
    ) -> dict[str, np.ndarray]:
        """The arrays ``names`` of one shard (all of :data:`SHARD_ARRAYS` by default)."""
        path = self.shard_path(shard)
        try:
            with np.load(path, allow_pickle=False) as archive:
                arrays = {name: archive[name] for name in names}
        except FileNotFoundError:
            raise FileFormatError(f"{path}: missing; rerun '{self.manifest['command']}'") from None
        except (KeyError, ValueError, OSError, zipfile.BadZipFile) as exc:
            raise FileFormatError(f"{path}: not a shard of this dataset ({exc})") from None
        return arrays

    def iter_shards(self) -> Iterator[dict[str, np.ndarray]]:
        """The shards in order, one in memory at a time."""
        for shard in range(self.shards):
            yield self.load_shard(shard)

    def iter_frames(self) -> Iterator[DatasetFrame]:
        """The frames in order, a shard in memory at a time."""
        for arrays in self.iter_shards():
            for j in range(len(arrays["rgb"])):
                yield DatasetFrame(
                    rgb=arrays["rgb"][j],
                    class_id=arrays["class_id"][j],
                    part_id=arrays["part_id"][j],
                    instance=arrays["instance"][j],
                    depth=arrays["depth"][j],
                    position=arrays["position"][j],
                    orientation=arrays["orientation"][j],
                    target=int(arrays["target"][j]),
                    world=self.worlds[int(arrays["world"][j])],
                    world_seed=int(arrays["world_seed"][j]),
                    appearance_seed=int(arrays["appearance_seed"][j]),
                )


def load_dataset(path: str | Path, complete: bool = True) -> Dataset:
    """The dataset in ``path``; with ``complete``, a clear error when shards are missing."""
    directory = Path(path)
    manifest = read_versioned_json(directory / MANIFEST, FORMAT, [VERSION])
    dataset = Dataset(directory, manifest)
    missing = dataset.missing_shards()
    if complete and missing:
        raise FileFormatError(
            f"{directory}: {len(missing)} of {dataset.shards} shards missing (first: "
            f"{shard_name(missing[0])}); rerun '{manifest.get('command')} --out {directory}'"
        )
    return dataset


@dataclass(frozen=True)
class DatasetStatistics:
    """Pixels per class and per part, frames per world: what a network would learn from."""

    frames: int
    pixels: int
    class_pixels: dict[str, int]
    part_pixels: dict[str, int]
    frames_per_world: dict[str, int]
    random_views: int

    def class_shares(self) -> dict[str, float]:
        return {name: count / max(self.pixels, 1) for name, count in self.class_pixels.items()}

    def summary(self) -> str:
        """One line: frames, worlds and the share of pixels per class."""
        shares = ", ".join(f"{name} {share:.1%}" for name, share in self.class_shares().items())
        worlds = ", ".join(f"{name} {count}" for name, count in self.frames_per_world.items())
        return (
            f"{self.frames} frames ({worlds}; {self.random_views} random views); pixels: {shares}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "frames": self.frames,
            "pixels": self.pixels,
            "class_pixels": self.class_pixels,
            "part_pixels": self.part_pixels,
            "frames_per_world": self.frames_per_world,
            "random_views": self.random_views,
        }


def dataset_statistics(path: str | Path | Dataset) -> DatasetStatistics:
    """Counts over every written shard of the dataset at ``path``."""
    dataset = path if isinstance(path, Dataset) else load_dataset(path, complete=False)
    classes = np.zeros(len(dataset.classes), np.int64)
    parts = np.zeros(len(dataset.parts), np.int64)
    worlds = np.zeros(len(dataset.worlds), np.int64)
    frames = random_views = 0
    for shard in range(dataset.shards):
        if not dataset.shard_path(shard).is_file():
            continue
        arrays = dataset.load_shard(shard, ("class_id", "part_id", "world", "target"))
        classes += np.bincount(arrays["class_id"].ravel(), minlength=len(classes))[: len(classes)]
        parts += np.bincount(arrays["part_id"].ravel(), minlength=len(parts))[: len(parts)]
        worlds += np.bincount(arrays["world"], minlength=len(worlds))[: len(worlds)]
        frames += len(arrays["world"])
        random_views += int(np.sum(arrays["target"] == 0))
    return DatasetStatistics(
        frames=frames,
        pixels=int(classes.sum()),
        class_pixels=dict(zip(dataset.classes, classes.tolist(), strict=True)),
        part_pixels=dict(zip(dataset.parts, parts.tolist(), strict=True)),
        frames_per_world=dict(zip(dataset.worlds, worlds.tolist(), strict=True)),
        random_views=random_views,
    )
