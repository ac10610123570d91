"""How well a detector reads a detector dataset's frames (:mod:`.shards`): the vehicle mask's
IoU, each part's IoU, detection precision and recall at IoU 0.5, and the CPU time per frame.

Any :class:`~seminspect.sensors.Detector` can be measured; the frames it is given carry the
dataset's colour image and depth (their label images are the dataset's, not a world's, so the
simulator's :class:`~seminspect.sensors.TruthDetector` cannot read them).
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.typing import NDArray

from seminspect.perception.shards import DatasetInfo, iterate_shards, read_dataset_info
from seminspect.sensors.camera import CameraModel, Frame
from seminspect.sensors.detector import Detector
from seminspect.sensors.segmentation import Detection

#: The classes whose union is "the vehicle mask".
VEHICLES = ("car", "truck")
MATCH_IOU = 0.5


@dataclass
class DetectorEvaluation:
    """Sums over the frames, and the figures read from them."""

    frames: int = 0
    true_positives: int = 0
    false_positives: int = 0
    false_negatives: int = 0
    vehicle: list[int] = field(default_factory=lambda: [0, 0])  # intersection, union
    parts: dict[str, list[int]] = field(default_factory=dict)
    cpu_s: float = 0.0
    wall_s: float = 0.0

    @property
    def vehicle_iou(self) -> float:
        return _ratio(*self.vehicle)

    @property
    def part_iou(self) -> dict[str, float]:
        """IoU per part that occurs in the truth or the detections."""
        return {name: _ratio(*sums) for name, sums in sorted(self.parts.items()) if sums[1]}

    @property
    def precision(self) -> float:
        return _ratio(self.true_positives, self.true_positives + self.false_positives)

    @property
    def recall(self) -> float:
        return _ratio(self.true_positives, self.true_positives + self.false_negatives)

    def summary(self) -> dict[str, object]:
        """The figures, JSON-ready (NaN where nothing was there to measure)."""
        per_frame = 1000 / max(self.frames, 1)
        counts = {k: v for k, v in asdict(self).items() if isinstance(v, int)}
        return counts | {
            "vehicle_iou": self.vehicle_iou,
            "part_iou": self.part_iou,
            "precision": self.precision,
            "recall": self.recall,
            "cpu_ms_per_frame": self.cpu_s * per_frame,
            "wall_ms_per_frame": self.wall_s * per_frame,
        }


def _ratio(numerator: float, denominator: float) -> float:
    return numerator / denominator if denominator else math.nan


def evaluate_detector(
    detector: Detector,
    dataset_dir: str | os.PathLike[str],
    *,
    min_area_px: int = 20,
    limit: int | None = None,
) -> DetectorEvaluation:
    """Run ``detector`` on every frame of the dataset (the first ``limit``), both levels.

    Ground-truth objects under ``min_area_px`` pixels are not counted; a detection matching
    one (IoU >= 0.5) is neither right nor wrong. The time per frame is the process's CPU time
    (all threads) and the wall time of the two ``detect`` calls, pre- and post-processing in.
    """
    info = read_dataset_info(dataset_dir)
    classes, parts = list(info.classes[1:]), list(info.parts[1:])
    result = DetectorEvaluation(parts={name: [0, 0] for name in parts})
    for shard in iterate_shards(info):
        for i in range(len(shard)):
            if limit is not None and result.frames >= limit:
                return result
            frame = dataset_frame(shard.rgb[i], shard.depth[i], result.frames)
            cpu, wall = time.process_time(), time.perf_counter()
            objects = detector.detect(frame, "instance", classes)
            found_parts = detector.detect(frame, "part", parts)
            result.cpu_s += time.process_time() - cpu
            result.wall_s += time.perf_counter() - wall
            truth = (shard.class_id[i], shard.part_id[i], shard.instance[i])
            _score_frame(result, info, truth, (objects, found_parts), min_area_px)
            result.frames += 1
    return result


def dataset_frame(rgb: NDArray[np.uint8], depth: NDArray[np.float16], stamp: float = 0.0) -> Frame:
    """A camera frame of a dataset frame: its colour image and depth (NaN read as inf)."""
    height, width = depth.shape
    metres = np.nan_to_num(depth.astype(np.float32), nan=np.inf)
    zeros = np.zeros((height, width), dtype=np.int32)
    return Frame(
        metres,
        zeros,
        zeros.astype(np.int16),
        zeros.astype(np.int16),
        None,
        zeros - 1,
        np.zeros(3),
        np.array([0.0, 0.0, 0.0, 1.0]),
        stamp,
        CameraModel(width=width, height=height),
        rgb=np.ascontiguousarray(rgb),
    )


def _score_frame(
    result: DetectorEvaluation,
    info: DatasetInfo,
    truth: tuple[NDArray[np.uint8], NDArray[np.uint8], NDArray[np.uint16]],
    found: tuple[list[Detection], list[Detection]],
    min_area_px: int,
) -> None:
    class_id, part_id, instance = truth
    objects, parts = found
    class_names, part_names = info.classes, info.parts
    vehicle_ids = [class_names.index(v) for v in VEHICLES]
    _add_iou(result.vehicle, np.isin(class_id, vehicle_ids), _union(objects, VEHICLES, class_id))
    for index, name in enumerate(part_names[1:], start=1):
        wanted = (part_id == index) & (class_id > 0)
        _add_iou(result.parts[name], wanted, _union(parts, (name,), class_id))
    matched, missed, wrong = _matches(
        _truth_objects(class_id, instance, class_names), objects, min_area_px
    )
    result.true_positives += matched
    result.false_negatives += missed
    result.false_positives += wrong


def _union(found: list[Detection], labels: tuple[str, ...], like: NDArray) -> NDArray[np.bool_]:
    mask = np.zeros(like.shape, dtype=bool)
    for detection in found:
        if detection.label in labels:
            mask |= detection.mask
    return mask


def _add_iou(sums: list[int], truth: NDArray[np.bool_], guess: NDArray[np.bool_]) -> None:
    sums[0] += int((truth & guess).sum())
    sums[1] += int((truth | guess).sum())


def _truth_objects(
    class_id: NDArray[np.uint8], instance: NDArray[np.uint16], names: tuple[str, ...]
) -> list[tuple[str, NDArray[np.bool_]]]:
    """``(class name, mask)`` of each ground-truth object: its pixels' most common class."""
    objects = []
    for value in np.unique(instance):
        if value == 0:
            continue
        mask = instance == value
        counts = np.bincount(class_id[mask], minlength=len(names))
        counts[0] = 0
        if counts.any():
            objects.append((names[int(counts.argmax())], mask))
    return objects


def _matches(
    truth: list[tuple[str, NDArray[np.bool_]]], found: list[Detection], min_area_px: int
) -> tuple[int, int, int]:
    """Matched, missed and wrong: detections best first, each taking the unmatched object of
    its label with the highest IoU, if that reaches :data:`MATCH_IOU`."""
    free = list(range(len(truth)))
    matched = wrong = 0
    for detection in sorted(found, key=lambda d: -d.score):
        ious = [
            (_iou(truth[k][1], detection.mask), k) for k in free if truth[k][0] == detection.label
        ]
        best, k = max(ious, default=(0.0, -1))
        if best < MATCH_IOU:
            wrong += 1
            continue
        free.remove(k)
        matched += int(truth[k][1].sum() >= min_area_px)
    missed = sum(1 for k in free if truth[k][1].sum() >= min_area_px)
    return matched, missed, wrong


def _iou(a: NDArray[np.bool_], b: NDArray[np.bool_]) -> float:
    union = int((a | b).sum())
    return int((a & b).sum()) / union if union else 0.0
