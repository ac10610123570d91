"""A tiny detector dataset in the format of seminspect.perception.dataset, drawn with numpy:
coloured rectangles ("cars", with dark "wheel" and light "window" parts) on a noisy
background, and the smoke training of the learned detector on it, shared by its tests."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from seminspect.core.io import save_npz_atomic, write_versioned_json
from seminspect.perception.dataset_format import FORMAT, MANIFEST, VERSION, shard_name

WIDTH, HEIGHT = 64, 48
CLASSES = ["background", "car", "truck", "building"]
PARTS = ["none", "wheel", "window"]
#: Small stage widths: the smoke training must learn in seconds on one core.
SMOKE_CHANNELS = (12, 24, 48)
SMOKE_STEPS = 200


def draw_frame(rng: np.random.Generator, cars: int) -> dict[str, np.ndarray]:
    """One frame: ``cars`` rectangles side by side (the first two touch when there are two)."""
    rgb = np.clip(rng.normal(rng.uniform(60, 140, 3), 12, (HEIGHT, WIDTH, 3)), 0, 255).astype(
        np.uint8
    )
    class_id = np.zeros((HEIGHT, WIDTH), np.uint8)
    part_id = np.zeros((HEIGHT, WIDTH), np.uint8)
    instance = np.zeros((HEIGHT, WIDTH), np.uint16)
    depth = np.full((HEIGHT, WIDTH), np.inf, np.float16)
    depth[HEIGHT // 2 :] = 8.0  # the ground
    x = int(rng.integers(2, 10))
    for k in range(1, cars + 1):
        w, h = int(rng.integers(16, 24)), int(rng.integers(12, 18))
        y = int(rng.integers(8, HEIGHT - h - 2))
        if x + w > WIDTH - 1:
            break
        paint = rng.choice([rng.uniform(170, 250), rng.uniform(0, 40)], 3)
        box = (slice(y, y + h), slice(x, x + w))
        rgb[box] = np.clip(rng.normal(paint, 8, (h, w, 3)), 0, 255).astype(np.uint8)
        class_id[box], instance[box], depth[box] = 1, k, 5.0 + k
        for wx in (x + 2, x + w - 6):  # wheels: dark squares on the bottom edge
            wheel = (slice(y + h - 4, y + h), slice(wx, wx + 4))
            rgb[wheel], part_id[wheel] = 15, 1
        window = (slice(y + 2, y + 5), slice(x + 4, x + w - 4))
        rgb[window], part_id[window] = (200, 220, 235), 2
        x += w if k == 1 and cars > 1 else w + int(rng.integers(3, 8))  # the first two touch
    return {
        "rgb": rgb,
        "class_id": class_id,
        "part_id": part_id,
        "instance": instance,
        "depth": depth,
    }


def write_dataset(root: Path, frames: int = 12, shard_size: int = 4, seed: int = 0) -> Path:
    """A dataset directory of ``frames`` frames in shards of ``shard_size``."""
    root.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    drawn = [draw_frame(rng, int(rng.integers(1, 3))) for _ in range(frames)]
    shards = []
    for index, first in enumerate(range(0, frames, shard_size)):
        chunk = drawn[first : first + shard_size]
        arrays = {name: np.stack([f[name] for f in chunk]) for name in chunk[0]}
        save_npz_atomic(root / shard_name(index), **arrays)
        shards.append({"file": shard_name(index), "frames": len(chunk)})
    manifest = {
        "classes": CLASSES,
        "parts": PARTS,
        "image_size": [WIDTH, HEIGHT],
        "frames": frames,
        "worlds": ["rectangles"],
        "shards": shards,
        "command": "tests/detector_data.py",
    }
    write_versioned_json(root / MANIFEST, FORMAT, VERSION, manifest)
    return root


@functools.cache
def smoke_training(base: Path) -> tuple[Path, object]:
    """The smoke training (once per test session and base directory): its dataset and run."""
    from seminspect.perception.training import train_detector

    data = write_dataset(base / "smoke-data", frames=16)
    result = train_detector(
        data,
        base / "smoke-run",
        steps=SMOKE_STEPS,
        batch=8,
        lr=5e-3,
        seed=0,
        eval_every=50,
        threads=1,
        channels=SMOKE_CHANNELS,
        val_fraction=0.25,
    )
    return data, result
