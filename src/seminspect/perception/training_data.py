"""The trainer's data: a detector dataset held in memory, split into training and held-out
frames, with the loss weights of its labels and the augmentations of :mod:`.training`.

Everything here is numpy: an augmentation draws from the generator it is given, so a run's
batches follow from its seed and resume from its saved generator state.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.perception.shards import DatasetInfo, iterate_shards, read_dataset_info

#: A weight is ``1 / sqrt(frequency)``, normalised to mean 1 and capped here.
MAX_WEIGHT = 10.0
NOISE_SIGMA = 0.02
MAX_SEAM_WEIGHT = 30.0


@dataclass(frozen=True)
class DetectorData:
    """The images and labels of every frame, and which frames train and which are held out."""

    info: DatasetInfo
    rgb: NDArray[np.uint8]  # (n, H, W, 3)
    classes: NDArray[np.uint8]  # (n, H, W)
    parts: NDArray[np.uint8]  # (n, H, W)
    edges: NDArray[np.bool_]  # (n, H, W): seams between touching instances
    train: NDArray[np.int64]
    val: NDArray[np.int64]
    class_weights: NDArray[np.float32]
    part_weights: NDArray[np.float32]
    flip_parts: NDArray[np.uint8]  # part id -> its mirror's (left <-> right)
    seam_weight: float  # of a seam pixel in the seams' loss
    fingerprint: dict[str, Any]


@dataclass(frozen=True)
class Batch:
    images: NDArray[np.float32]  # (B, 3, h, w) in [0, 1]
    classes: NDArray[np.uint8]
    parts: NDArray[np.uint8]
    edges: NDArray[np.bool_]


def load_data(dataset_dir: str | os.PathLike[str], val_fraction: float) -> DetectorData:
    """The whole dataset in memory (its depth left out), held out as :mod:`.training` says."""
    info = read_dataset_info(dataset_dir)
    rgb, classes, parts, edges, sizes = [], [], [], [], []
    for shard in iterate_shards(info):
        rgb.append(shard.rgb)
        classes.append(shard.class_id)
        parts.append(shard.part_id)
        edges.append(seams(shard.instance))
        sizes.append(len(shard))
    train, val = split(sizes, val_fraction)
    if not len(train):
        raise FileFormatError(f"{info.root}: no frames left to train on")
    data = np.concatenate(classes), np.concatenate(parts)
    fingerprint = {
        "image_size": list(info.image_size),
        "shards": [[p.name, n, p.stat().st_size] for p, n in zip(info.shards, sizes, strict=True)],
    }
    return DetectorData(
        info,
        np.concatenate(rgb),
        data[0],
        data[1],
        np.concatenate(edges),
        train,
        val,
        label_weights(data[0][train], len(info.classes)),
        label_weights(data[1][train][data[0][train] > 0], len(info.parts)),
        mirror_parts(info.parts),
        seam_weight(np.concatenate(edges)[train]),
        fingerprint,
    )


def split(sizes: list[int], val_fraction: float) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Training and held-out frame indices: the last ``val_fraction`` of the shards (at least
    one, never all), or of the frames when there is a single shard."""
    total = sum(sizes)
    if val_fraction <= 0 or total < 2:
        return np.arange(total), np.zeros(0, dtype=np.int64)
    if len(sizes) >= 2:
        held = min(max(1, round(val_fraction * len(sizes))), len(sizes) - 1)
        first = sum(sizes[:-held])
    else:
        first = total - min(max(1, round(val_fraction * total)), total - 1)
    return np.arange(first), np.arange(first, total)


def label_weights(labels: NDArray[np.uint8], count: int) -> NDArray[np.float32]:
    """``1 / sqrt(frequency)`` per label, mean 1 over the labels seen, capped at
    :data:`MAX_WEIGHT`; a label never seen gets the cap."""
    counts = np.bincount(labels.ravel(), minlength=count)[:count].astype(np.float64)
    seen = counts > 0
    weights = np.full(count, MAX_WEIGHT)
    if seen.any():
        raw = 1 / np.sqrt(counts[seen] / counts.sum())
        weights[seen] = np.minimum(raw / raw.mean(), MAX_WEIGHT)
    return weights.astype(np.float32)


def seam_weight(edges: NDArray[np.bool_]) -> float:
    """``sqrt(other pixels / seam pixels)`` within [1, :data:`MAX_SEAM_WEIGHT`]: seams cover
    well under 1 % of an image, and unweighted the head would learn to see none."""
    seam = int(edges.sum())
    return float(np.clip(np.sqrt((edges.size - seam) / max(seam, 1)), 1, MAX_SEAM_WEIGHT))


def seams(instance: NDArray[np.integer]) -> NDArray[np.bool_]:
    """Pixels of an instance with a 4-neighbour of another (not none): where two touching
    objects meet, two pixels wide."""
    out = np.zeros(instance.shape, dtype=bool)
    for axis in (-1, -2):
        size = instance.shape[axis]
        a = np.take(instance, range(size - 1), axis=axis)
        b = np.take(instance, range(1, size), axis=axis)
        meet = (a != b) & (a > 0) & (b > 0)
        lower = [slice(None)] * instance.ndim
        upper = [slice(None)] * instance.ndim
        lower[axis], upper[axis] = slice(0, size - 1), slice(1, size)
        out[tuple(lower)] |= meet
        out[tuple(upper)] |= meet
    return out


def mirror_parts(parts: tuple[str, ...]) -> NDArray[np.uint8]:
    """The part each part becomes in a mirrored image: ``front-left-door`` <->
    ``front-right-door`` where both exist, every other part itself."""
    index = {name: i for i, name in enumerate(parts)}
    swap = {"left": "right", "right": "left"}
    pattern = re.compile(r"(?<![a-z])(left|right)(?![a-z])")
    mirrored = [
        index.get(pattern.sub(lambda m: swap[m.group(1)], p), i) for i, p in enumerate(parts)
    ]
    return np.asarray(mirrored, dtype=np.uint8)


def augmented(
    data: DetectorData, frames: NDArray[np.int64], crop: float, rng: np.random.Generator
) -> Batch:
    """The frames as one batch of random crops (one size), flips and colour changes."""
    height, width = data.info.shape
    rows, cols = max(8, round(height * crop)), max(8, round(width * crop))
    rows, cols = min(rows, height), min(cols, width)
    images = np.empty((len(frames), 3, rows, cols), dtype=np.float32)
    labels = np.empty((3, len(frames), rows, cols), dtype=np.uint8)
    for slot, frame in enumerate(frames):
        y0 = int(rng.integers(0, height - rows + 1))
        x0 = int(rng.integers(0, width - cols + 1))
        window = (frame, slice(y0, y0 + rows), slice(x0, x0 + cols))
        image = data.rgb[window].astype(np.float32) / 255
        cut = [data.classes[window], data.parts[window], data.edges[window].view(np.uint8)]
        if rng.random() < 0.5:
            image, cut = image[:, ::-1], [c[:, ::-1] for c in cut]
            cut[1] = data.flip_parts[cut[1]]
        images[slot] = _recoloured(image, rng).transpose(2, 0, 1)
        labels[:, slot] = cut
    return Batch(images, labels[0], labels[1], labels[2].astype(bool))


def _recoloured(image: NDArray[np.floating], rng: np.random.Generator) -> NDArray[np.float32]:
    """Contrast, brightness and per-channel gains at random, then sensor noise."""
    contrast, brightness = rng.uniform(0.75, 1.25), rng.uniform(0.7, 1.3)
    gains = (brightness * rng.uniform(0.9, 1.1, 3)).astype(np.float32)
    mean = image.mean()
    out = ((image - mean) * np.float32(contrast) + mean) * gains
    out += rng.standard_normal(out.shape, dtype=np.float32) * np.float32(NOISE_SIGMA)
    return np.clip(out, 0, 1).astype(np.float32, copy=False)
