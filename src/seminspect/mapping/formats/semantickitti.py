"""SemanticKITTI scans: ``.bin`` points, ``.label`` labels, ``poses.txt`` and ``calib.txt``.

A scan is ``float32`` rows ``x y z remission`` in the Velodyne frame; its label file holds one
``uint32`` per point, the semantic id in the lower 16 bits and the instance id in the upper 16.
Semantic ids are named through the dataset's published label table (shipped as package data).
Poses are KITTI odometry poses of the left camera (``cam0``), 3x4 row-major per line; with the
calibration's ``Tr`` (Velodyne to cam0) the Velodyne pose of scan ``i`` in the frame of scan 0's
Velodyne is ``inv(Tr) @ P_i @ Tr``.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.ingest import integrate_labelled_scan
from seminspect.mapping.semantic_cloud import SemanticCloud, as_transform, transform_points
from seminspect.perception.encoders import Encoder

#: Training classes 1-8 (car .. motorcyclist) are the instance-labelled "things".
_THING_CLASSES = range(1, 9)


@dataclass(frozen=True)
class LabelTable:
    """SemanticKITTI's label table: raw id -> name, raw id -> training class and back."""

    names: dict[int, str]
    learning_map: dict[int, int]
    learning_map_inv: dict[int, int]

    def thing_classes(self) -> dict[int, str]:
        """Training classes whose points carry instance ids (SemanticKITTI's "things", 1-8)."""
        return {c: self.names[self.learning_map_inv[c]] for c in _THING_CLASSES}


@functools.cache
def label_table() -> LabelTable:
    """The published SemanticKITTI label table."""
    text = resources.files("seminspect.mapping").joinpath("data/semantic_kitti_labels.json")
    document = json.loads(text.read_text(encoding="utf-8"))
    return LabelTable(
        names={int(k): v for k, v in document["labels"].items()},
        learning_map={int(k): int(v) for k, v in document["learning_map"].items()},
        learning_map_inv={int(k): int(v) for k, v in document["learning_map_inv"].items()},
    )


@dataclass
class KittiScan:
    """One labelled scan in its sensor frame."""

    points: NDArray[np.float64]
    remission: NDArray[np.float32]
    semantic: NDArray[np.int64] | None
    instance: NDArray[np.int64] | None


def read_scan(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.float32]]:
    """Points ``(N, 3)`` and remission ``(N,)`` of a Velodyne ``.bin`` scan."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    raw = source.read_bytes()
    if len(raw) == 0 or len(raw) % 16:
        raise FileFormatError(
            f"{source}: {len(raw)} bytes is not a whole number of 16-byte points (x y z remission)"
        )
    rows = np.frombuffer(raw, dtype="<f4").reshape(-1, 4)
    if not np.all(np.isfinite(rows[:, :3])):
        raise FileFormatError(f"{source}: scan has NaN or infinite coordinates")
    return rows[:, :3].astype(np.float64), rows[:, 3].copy()


def read_labels(path: str | Path, points: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Semantic ids and instance ids of a ``.label`` file for a scan of ``points`` points."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    raw = source.read_bytes()
    if len(raw) != 4 * points:
        raise FileFormatError(
            f"{source}: {len(raw)} bytes of labels for a scan of {points} points "
            f"(expected {4 * points})"
        )
    values = np.frombuffer(raw, dtype="<u4")
    semantic = (values & 0xFFFF).astype(np.int64)
    unknown = sorted(set(np.unique(semantic).tolist()) - set(label_table().names))
    if unknown:
        raise FileFormatError(f"{source}: semantic ids {unknown[:5]} are not in the label table")
    return semantic, (values >> 16).astype(np.int64)


def read_kitti_scan(scan: str | Path, labels: str | Path | None = None) -> KittiScan:
    points, remission = read_scan(scan)
    if labels is None:
        return KittiScan(points, remission, None, None)
    semantic, instance = read_labels(labels, points.shape[0])
    return KittiScan(points, remission, semantic, instance)


def read_calib(path: str | Path) -> dict[str, NDArray[np.float64]]:
    """The 3x4 matrices of a KITTI ``calib.txt`` (``P0``..``P3``, ``Tr``) by name."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    matrices = {}
    for number, line in enumerate(source.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip():
            continue
        key, sep, values = line.partition(":")
        try:
            matrix = np.array(values.split(), dtype=np.float64)
        except ValueError:
            matrix = np.zeros(0)
        if not sep or matrix.size != 12 or not np.all(np.isfinite(matrix)):
            raise FileFormatError(f"{source}: line {number} is not 'NAME: 12 numbers'")
        matrices[key.strip()] = matrix.reshape(3, 4)
    if "Tr" not in matrices:
        raise FileFormatError(f"{source}: no Tr (Velodyne to camera) calibration")
    return matrices


def read_poses(path: str | Path) -> NDArray[np.float64]:
    """KITTI odometry poses as ``(M, 4, 4)`` matrices (one 3x4 row-major pose per line)."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    poses = []
    for number, line in enumerate(source.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip():
            continue
        try:
            values = np.array(line.split(), dtype=np.float64)
        except ValueError:
            values = np.zeros(0)
        if values.size != 12:
            raise FileFormatError(f"{source}: line {number} is not 12 numbers (a 3x4 pose)")
        pose = np.vstack([values.reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])
        try:
            poses.append(as_transform(pose, f"pose on line {number}"))
        except InvalidInputError as exc:
            raise FileFormatError(f"{source}: {exc}") from None
    if not poses:
        raise FileFormatError(f"{source}: no poses")
    return np.stack(poses)


def velodyne_poses(camera_poses: NDArray[np.float64], Tr: NDArray[np.float64]) -> NDArray:
    """Velodyne poses in the frame of the first scan's Velodyne: ``inv(Tr) @ P_i @ Tr``."""
    tr = np.vstack([np.asarray(Tr, dtype=np.float64).reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])
    tr = as_transform(tr, "calibration Tr")
    return np.linalg.inv(tr) @ camera_poses @ tr


def instance_boxes(
    points: NDArray[np.float64],
    semantic: NDArray[np.int64],
    instance: NDArray[np.int64],
    learning_class: int,
    min_points: int = 1,
) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Axis-aligned boxes of the labelled instances of one training class.

    Raw ids that share a training class (``car`` and ``moving-car``) count as one class; an
    instance is a (training class, instance id) pair, consistent across a sequence's scans.
    """
    mapping = label_table().learning_map
    ids = [raw for raw, cls in mapping.items() if cls == learning_class]
    chosen = np.isin(semantic, ids) & (instance > 0)
    boxes = []
    for value in np.unique(instance[chosen]):
        members = points[chosen & (instance == value)]
        if members.shape[0] >= min_points:
            boxes.append((members.min(axis=0), members.max(axis=0)))
    return boxes


@dataclass
class FusedScans:
    """Several posed, labelled scans fused into one cloud, with their labels in the world frame."""

    cloud: SemanticCloud
    points: NDArray[np.float64]
    semantic: NDArray[np.int64]
    instance: NDArray[np.int64]


def frame_number(scan: str | Path) -> int:
    """The frame index of a KITTI scan file name (``000042.bin`` -> 42)."""
    stem = Path(scan).stem
    if not stem.isdigit():
        raise InvalidInputError(f"{scan}: KITTI scans are named by frame number, e.g. 000042.bin")
    return int(stem)


def fuse_kitti_scans(
    scans: Sequence[tuple[Path, Path]],
    poses: NDArray[np.float64] | None,
    encoder: Encoder,
    radius: float,
    on_scan: Callable[[int], None] | None = None,
) -> FusedScans:
    """Fuse labelled scans, each one view, posed by frame number (001 Sec III-A.3).

    ``poses`` are Velodyne poses (:func:`velodyne_poses`); without them only one scan may be
    given and it stays in its own frame.
    """
    if poses is None and len(scans) != 1:
        raise InvalidInputError("fusing several scans needs their poses (--poses and --calib)")
    cloud = SemanticCloud.empty(encoder.dim, encoder.name)
    names = label_table().names
    world, semantic, instance = [], [], []
    for k, (scan_path, label_path) in enumerate(scans):
        points, _ = read_scan(scan_path)
        semantic_ids, instance_ids = read_labels(label_path, points.shape[0])
        pose = np.eye(4)
        if poses is not None:
            frame = frame_number(scan_path)
            if frame >= poses.shape[0]:
                raise InvalidInputError(
                    f"{scan_path}: frame {frame} has no pose ({poses.shape[0]})"
                )
            pose = poses[frame]
        integrate_labelled_scan(
            cloud, points, semantic_ids, pose, names=names, encoder=encoder, radius=radius
        )
        world.append(transform_points(pose, points))
        semantic.append(semantic_ids)
        instance.append(instance_ids)
        if on_scan:
            on_scan(k)
    return FusedScans(
        cloud, np.concatenate(world), np.concatenate(semantic), np.concatenate(instance)
    )
