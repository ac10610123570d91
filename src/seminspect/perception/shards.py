"""What the learned detector reads of a detector dataset (:mod:`.dataset`, format
``seminspect.detector-dataset`` v1): the label vocabularies, the image size, and per shard the
colour renders and their per-pixel labels, checked against each other.

Files are opened by :func:`.dataset_format.load_dataset` (the dataset's own reader: its errors
for missing shards name the command that finishes them); this module adds the checks a
trainer needs and leaves the shard's poses and seeds unread. Used by :mod:`.training` and
:func:`.evaluation.evaluate_detector`, without torch.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.perception.dataset_format import MANIFEST, Dataset, load_dataset

#: The target classes a detector dataset labels, index 0 the background.
CLASSES = ("background", "car", "truck", "building")
#: The arrays of a shard read here, with their dtypes: ``rgb`` (n, H, W, 3), the others
#: (n, H, W): ``class_id`` and ``part_id`` index ``classes`` and ``parts``, ``instance`` is
#: 0 (none) or 1..k per frame, ``depth`` in metres.
READ_ARRAYS = {
    "rgb": np.uint8,
    "class_id": np.uint8,
    "part_id": np.uint8,
    "instance": np.uint16,
    "depth": np.float16,
}


@dataclass(frozen=True)
class DatasetInfo:
    """What ``dataset.json`` declares: the label vocabularies, the image size ``(W, H)`` and
    the shard files in order."""

    dataset: Dataset
    classes: tuple[str, ...]
    parts: tuple[str, ...]
    image_size: tuple[int, int]
    shards: tuple[Path, ...]

    @property
    def root(self) -> Path:
        return self.dataset.path

    @property
    def shape(self) -> tuple[int, int]:
        """Image rows and columns ``(H, W)``."""
        return self.image_size[1], self.image_size[0]


@dataclass(frozen=True)
class Shard:
    """The frames of one shard file, arrays as :data:`READ_ARRAYS` names them."""

    path: Path
    rgb: NDArray[np.uint8]
    class_id: NDArray[np.uint8]
    part_id: NDArray[np.uint8]
    instance: NDArray[np.uint16]
    depth: NDArray[np.float16]

    def __len__(self) -> int:
        return len(self.rgb)


def read_dataset_info(dataset_dir: str | os.PathLike[str]) -> DatasetInfo:
    """The dataset's ``dataset.json``, checked, every shard of it written."""
    dataset = load_dataset(Path(dataset_dir))
    source = dataset.path / MANIFEST
    doc = dataset.manifest
    classes, parts = doc.get("classes"), doc.get("parts")
    if not _names(classes) or tuple(classes) != CLASSES:  # type: ignore[arg-type]
        raise FileFormatError(f"{source}: 'classes' must be {list(CLASSES)}, got {classes!r}")
    if not _names(parts) or parts[0] != "none":  # type: ignore[index]
        raise FileFormatError(f"{source}: 'parts' must be names, 'none' first, got {parts!r}")
    size = doc.get("image_size")
    if not (
        isinstance(size, list) and len(size) == 2 and all(type(v) is int and v > 0 for v in size)
    ):
        raise FileFormatError(f"{source}: 'image_size' must be [width, height], got {size!r}")
    if not isinstance(doc.get("shards"), list) or not doc["shards"]:
        raise FileFormatError(f"{source}: a dataset without shards")
    shards = tuple(dataset.shard_path(k) for k in range(dataset.shards))
    return DatasetInfo(dataset, CLASSES, tuple(parts), (size[0], size[1]), shards)  # type: ignore[arg-type]


def _names(value: object) -> bool:
    return (
        isinstance(value, list)
        and len(value) > 0
        and all(isinstance(v, str) and v for v in value)
        and len(set(value)) == len(value)
    )


def read_shard(info: DatasetInfo, shard: int) -> Shard:
    """Shard number ``shard``, every array checked against the others and against ``info``."""
    path = info.shards[shard]
    arrays = info.dataset.load_shard(shard, tuple(READ_ARRAYS))
    count = len(arrays["rgb"])
    height, width = info.shape
    for name, dtype in READ_ARRAYS.items():
        shape = (count, height, width, 3) if name == "rgb" else (count, height, width)
        if arrays[name].shape != shape or arrays[name].dtype != dtype:
            raise FileFormatError(
                f"{path}: {name} is {arrays[name].dtype} {list(arrays[name].shape)}, expected "
                f"{np.dtype(dtype)} {list(shape)}"
            )
    for name, names in (("class_id", info.classes), ("part_id", info.parts)):
        if count and int(arrays[name].max()) >= len(names):
            raise FileFormatError(f"{path}: {name} {int(arrays[name].max())} names no label")
    return Shard(path, **arrays)


def iterate_shards(dataset_dir: str | os.PathLike[str] | DatasetInfo) -> Iterator[Shard]:
    """The dataset's shards in order, one in memory at a time."""
    info = dataset_dir if isinstance(dataset_dir, DatasetInfo) else read_dataset_info(dataset_dir)
    for shard in range(len(info.shards)):
        yield read_shard(info, shard)
