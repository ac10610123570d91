"""Simulated instance and part segmentation, derived from a frame's ground-truth labels.

A detection is what a segmentation model (YOLOv8-seg in 000 Sec VI-B) reports: a label, a mask,
the mask's area in pixels and a confidence score. The ground-truth instance id is attached for
evaluation only (-1 for false positives). The faults of :class:`NoiseModel` are applied in this
order: erosion, bleeding into the background (pixels of instance 0), the minimum area, missed
detections, confidence noise, and finally false positives (random ellipses).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, cast

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.sensors.camera import Frame
from seminspect.sensors.noise import NoiseModel, require_rng
from seminspect.worlds import World

Level = Literal["instance", "part"]


@dataclass(eq=False)
class Detection:
    """One segmented object or part.

    Attributes:
        label: class name (``car``) for objects, part name (``hood``) for parts.
        mask: ``bool`` (H, W) pixels of the detection.
        area_px: number of mask pixels.
        score: confidence in (0, 1].
        bbox: ``(x0, y0, x1, y1)`` pixel box, upper bounds exclusive.
        instance_id: ground-truth object id, for evaluation only; -1 for a false positive.
        level: ``"instance"`` or ``"part"``.
        depth_m: median finite depth under the mask (``inf`` if none).
    """

    label: str
    mask: NDArray[np.bool_]
    area_px: int
    score: float
    bbox: tuple[int, int, int, int]
    instance_id: int
    level: Level
    depth_m: float

    @property
    def is_false_positive(self) -> bool:
        return self.instance_id < 0


def as_level(level: str) -> Level:
    """``level`` checked: ``"instance"`` or ``"part"``."""
    if level in {"instance", "part"}:
        return cast("Level", level)
    raise InvalidInputError(f"detection level must be 'instance' or 'part', got {level!r}")


Window = tuple[slice, slice]
_WHOLE: Window = (slice(0, None), slice(0, None))


def _bbox(mask: NDArray[np.bool_], window: Window = _WHOLE) -> tuple[int, int, int, int]:
    """The box of a mask cut out of a frame at ``window``, in frame pixels."""
    rows = np.flatnonzero(mask.any(axis=1)) + window[0].start
    cols = np.flatnonzero(mask.any(axis=0)) + window[1].start
    return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1


def _median_depth(depth: NDArray[np.float32], mask: NDArray[np.bool_]) -> float:
    values = depth[mask]
    values = values[np.isfinite(values)]
    return float(np.median(values)) if len(values) else math.inf


@numba.njit(cache=True)
def _boxes(key: NDArray[np.integer], values: NDArray[np.int64]) -> NDArray[np.int64]:
    """Rows and columns ``[r0, c0, r1, c1)`` spanned by each of the sorted ``values`` in ``key``.

    One pass over the frame for every candidate at once; a value absent from ``key`` gets an
    empty box.
    """
    height, width = key.shape
    boxes = np.empty((len(values), 4), np.int64)
    boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3] = height, width, 0, 0
    last_value, last_slot = np.int64(0), -1
    for r in range(height):
        for c in range(width):
            value = key[r, c]
            if value <= 0:
                continue
            if value != last_value:  # runs of one label are the rule along a row
                last_value = value
                last_slot = np.searchsorted(values, value)
                if last_slot == len(values) or values[last_slot] != value:
                    last_slot = -1
            if last_slot >= 0:
                box = boxes[last_slot]
                box[0], box[1] = min(box[0], r), min(box[1], c)
                box[2], box[3] = max(box[2], r + 1), max(box[3], c + 1)
    return boxes


def _window(box: NDArray[np.int64], margin: int, shape: tuple[int, int]) -> Window:
    """``box`` grown by ``margin`` pixels on every side, within the frame."""
    r0, c0, r1, c1 = (int(b) for b in box)
    return (
        slice(max(r0 - margin, 0), min(r1 + margin, shape[0])),
        slice(max(c0 - margin, 0), min(c1 + margin, shape[1])),
    )


def _in_frame(mask: NDArray[np.bool_], window: Window, shape: tuple[int, int]) -> NDArray[np.bool_]:
    full = np.zeros(shape, dtype=bool)
    full[window] = mask
    return full


def _distort(mask: NDArray[np.bool_], background: NDArray[np.bool_], noise: NoiseModel):
    """Erode the mask, then let it bleed into neighbouring background pixels."""
    shaped: NDArray[Any] = mask.astype(np.uint8)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    if noise.mask_erosion_px:
        shaped = cv2.erode(shaped, kernel, iterations=noise.mask_erosion_px)
    if noise.mask_bleed_px:
        grown = cv2.dilate(shaped, kernel, iterations=noise.mask_bleed_px).astype(bool)
        return shaped.astype(bool) | (grown & background)
    return shaped.astype(bool)


def key_boxes(key: NDArray[np.integer]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The distinct values above 0 of a 2D ``key``, ascending (``np.unique(key[key > 0])``),
    and the rows and columns ``[r0, c0, r1, c1)`` each spans.

    Two compiled passes (the largest value, then a table indexed by value) instead of numpy's
    mask, sort and a third pass for the boxes; values too large for a small table fall back to
    sorting.
    """
    top = _largest(key)
    if top > key.size:
        values = np.unique(key[key > 0]).astype(np.int64)
        return values, _boxes(key, values)
    return _tabled_boxes(key, top)


@numba.njit(cache=True)
def _largest(key: NDArray[np.integer]) -> int:
    top = 0
    for r in range(key.shape[0]):
        for c in range(key.shape[1]):
            top = max(top, key[r, c])
    return top


@numba.njit(cache=True)
def _tabled_boxes(
    key: NDArray[np.integer], top: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`key_boxes` with a table of ``top + 1`` boxes, one per possible value."""
    height, width = key.shape
    table = np.empty((top + 1, 4), np.int64)
    table[:, 0], table[:, 1], table[:, 2], table[:, 3] = height, width, 0, 0
    for r in range(height):
        for c in range(width):
            value = key[r, c]
            if value > 0:
                box = table[value]
                box[0], box[1] = min(box[0], r), min(box[1], c)
                box[2], box[3] = max(box[2], r + 1), max(box[3], c + 1)
    values = np.flatnonzero(table[:, 2] > 0).astype(np.int64)
    return values, table[values]


def _keys(
    frame: Frame, world: World, level: Level, classes, parts
) -> tuple[NDArray, list, NDArray[np.int64]]:
    """Per-pixel grouping key, the (key, label, instance) of every candidate and its box.

    Classes and parts are matched by name; names absent from this world match nothing (a
    mission looking for trucks in a world of cars simply finds none).
    """
    wanted = None if classes is None else set(classes)
    wanted_parts = None if parts is None else set(parts)
    stride = len(world.part_names)
    key: NDArray[np.integer] = (
        frame.instance if level == "instance" else _part_keys(frame.instance, frame.part_id, stride)
    )
    values, boxes = key_boxes(key)
    candidates, kept = [], []
    for slot, value in enumerate(values.tolist()):
        inst = value if level == "instance" else value // stride
        info = world.instances.get(inst)
        if info is None or (wanted is not None and info.class_name not in wanted):
            continue
        label = info.class_name if level == "instance" else world.part_names[value % stride]
        if level == "instance" or wanted_parts is None or label in wanted_parts:
            candidates.append((value, label, inst))
            kept.append(slot)
    return key, candidates, boxes[np.asarray(kept, dtype=np.intp)]


@numba.njit(cache=True)
def _part_keys(
    instance: NDArray[np.int32], part_id: NDArray[np.int16], stride: int
) -> NDArray[np.int64]:
    """``instance * stride + part_id`` per pixel, 0 where there is no part: one pass."""
    key = np.zeros(instance.shape, np.int64)
    for r in range(instance.shape[0]):
        for c in range(instance.shape[1]):
            if part_id[r, c] != 0:
                key[r, c] = np.int64(instance[r, c]) * stride + part_id[r, c]
    return key


def detect(
    frame: Frame,
    world: World,
    level: Level = "instance",
    *,
    classes: Iterable[str] | None = None,
    parts: Iterable[str] | None = None,
    noise: NoiseModel | None = None,
    rng: np.random.Generator | None = None,
) -> list[Detection]:
    """Segment the objects (``level="instance"``) or their parts (``level="part"``).

    Args:
        classes: object classes to report (all when ``None``); for parts, the classes of the
            objects whose parts are reported.
        parts: part names to report (all when ``None``); ignored for objects.
        noise: segmentation faults (``None``: ideal).
        rng: generator for the faults; required when the noise model is not ideal.
    """
    level = as_level(level)
    model = noise or NoiseModel()
    generator = None if model.is_ideal else require_rng(rng)
    key, candidates, boxes = _keys(frame, world, level, classes, parts)
    # Each mask is worked on in its box grown by more than the bleed: the pixels around it are
    # background-free zeros, so erosion and dilation see what they would see in the whole
    # frame, and where the box meets the frame's edge the window's edge is the frame's.
    margin = model.mask_bleed_px + 1
    detections = []
    for (value, label, inst), box in zip(candidates, boxes, strict=True):
        window = _window(box, margin, frame.shape)
        mask = key[window] == value
        if generator is not None:
            mask = _distort(mask, frame.instance[window] == 0, model)
        area = int(np.count_nonzero(mask))
        if area < model.min_mask_area_px:
            continue
        depth = _median_depth(frame.depth[window], mask)
        if generator is not None and generator.random() < model.miss_chance(depth, area):
            continue
        score = model.score_mean
        if generator is not None and model.score_sigma:
            score = float(np.clip(generator.normal(model.score_mean, model.score_sigma), 0.01, 1.0))
        full = _in_frame(mask, window, frame.shape)
        detections.append(
            Detection(label, full, area, score, _bbox(mask, window), inst, level, depth)
        )
    if generator is not None and model.false_positives_per_frame:
        labels = _false_positive_labels(world, level, classes, parts)
        detections += _false_positives(frame, labels, level, model, generator)
    return detections


def detect_instances(
    frame: Frame,
    world: World,
    classes: Iterable[str] | None = None,
    noise: NoiseModel | None = None,
    rng: np.random.Generator | None = None,
) -> list[Detection]:
    """Object detections of the given classes (``car``, ``truck``, ``building``, ...)."""
    return detect(frame, world, "instance", classes=classes, noise=noise, rng=rng)


def detect_parts(
    frame: Frame,
    world: World,
    noise: NoiseModel | None = None,
    rng: np.random.Generator | None = None,
    *,
    classes: Iterable[str] | None = None,
    parts: Iterable[str] | None = None,
) -> list[Detection]:
    """Part detections (``hood``, ``window``, ...), optionally of some object classes only."""
    return detect(frame, world, "part", classes=classes, parts=parts, noise=noise, rng=rng)


def _false_positive_labels(world: World, level: Level, classes, parts) -> Sequence[str]:
    if level == "instance":
        return (
            sorted(classes)
            if classes is not None
            else sorted({i.class_name for i in world.instances.values()})
        )
    return sorted(parts) if parts is not None else world.part_names[1:]


def _false_positives(
    frame: Frame,
    labels: Sequence[str],
    level: Level,
    noise: NoiseModel,
    rng: np.random.Generator,
) -> list[Detection]:
    """Poisson-many random elliptical masks with made-up labels and modest scores."""
    if not labels:
        return []
    height, width = frame.shape
    result = []
    for _ in range(int(rng.poisson(noise.false_positives_per_frame))):
        canvas = np.zeros((height, width), dtype=np.uint8)
        centre = (int(rng.integers(width)), int(rng.integers(height)))
        axes = (int(rng.integers(8, 60)), int(rng.integers(8, 60)))
        cv2.ellipse(canvas, centre, axes, float(rng.uniform(0, 180)), 0, 360, 1, -1)
        mask = canvas.astype(bool)
        score = float(np.clip(rng.normal(noise.false_positive_score, 0.1), 0.01, 1.0))
        label = labels[int(rng.integers(len(labels)))]
        area = int(mask.sum())
        result.append(
            Detection(
                label, mask, area, score, _bbox(mask), -1, level, _median_depth(frame.depth, mask)
            )
        )
    return result
