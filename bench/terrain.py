"""Phase 2 of 001 (the task-driven terrain scene graph) on a 1,000,000-point cloud, by stage.

A synthetic town block: two crossing asphalt roads lined with sidewalks, grass elsewhere, parked
cars and trees. Every point carries its class's MiniLM caption embedding plus per-point noise, as
a phase-1 cloud would after averaging. Run: ``.venv/bin/python bench/terrain.py``.
"""

from __future__ import annotations

import time

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.semantic_cloud import SemanticCloud
from seminspect.perception.encoders import CaptionEncoder, MiniLMTextEncoder, normalize_rows

POINTS = 1_000_000
CLASSES = ("road", "sidewalk", "grass", "car", "tree")


def town(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    cars, trees = 60, 60
    per_car, per_tree = 2500, 1500
    n_ground = POINTS - cars * per_car - trees * per_tree
    ground = np.column_stack([rng.uniform(-100, 100, (n_ground, 2)), rng.normal(0, 0.02, n_ground)])
    distance = np.minimum(np.abs(ground[:, 0]), np.abs(ground[:, 1]))  # to the nearer road axis
    labels = np.where(distance < 5, 0, np.where(distance < 8, 1, 2))
    parts, part_labels = [ground], [labels]
    for _ in range(cars):
        along, side = rng.uniform(-95, 95), rng.choice([-3.0, 3.0])
        low = (
            np.array([along, side - 1, 0.2])
            if rng.random() < 0.5
            else np.array([side - 1, along, 0.2])
        )
        size = np.array([4.2, 1.8, 1.4]) if low[1] == side - 1 else np.array([1.8, 4.2, 1.4])
        parts.append(low + rng.uniform(0, 1, (per_car, 3)) * size)
        part_labels.append(np.full(per_car, 3))
    for _ in range(trees):
        centre = rng.uniform(12, 95, 2) * rng.choice([-1, 1], 2)
        angle, height = rng.uniform(0, 2 * np.pi, per_tree), rng.uniform(0, 6, per_tree)
        radius = np.where(height > 2.5, 1.5, 0.3)
        offsets = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), height])
        parts.append(np.array([*centre, 0.0]) + offsets)
        part_labels.append(np.full(per_tree, 4))
    return np.vstack(parts), np.concatenate(part_labels)


def main() -> None:
    rng = make_rng(0, "bench", "terrain")
    start = time.perf_counter()
    encoder = CaptionEncoder(MiniLMTextEncoder())
    clean = encoder.encode_labels(list(CLASSES))
    load = time.perf_counter() - start
    points, labels = town(rng)
    noise = rng.standard_normal((POINTS, encoder.dim), dtype=np.float32) * (0.3 / np.sqrt(384))
    embeddings = normalize_rows(clean[labels] + noise)
    cloud = SemanticCloud(points, embeddings, np.ones(POINTS, np.int64), encoder.name)
    prompts = TaskPrompts.parse("sidewalk,grass,asphalt", "image of a tree,image of a car")
    build_terrain_graph(cloud, prompts, encoder)  # warm-up: numba/sklearn first calls
    began = time.perf_counter()
    build = build_terrain_graph(cloud, prompts, encoder)
    total = time.perf_counter() - began
    print(f"MiniLM load + caption embeddings (once, not phase 2): {load:.1f} s")
    print(f"cloud: {len(cloud):,} points, {cloud.dim}-d embeddings")
    for stage, seconds in build.timings.items():
        print(f"  {stage:<9} {seconds:6.2f} s")
    print(f"phase 2 total: {total:.2f} s (target < 20 s)")
    print("summary:", build.scene.summary())


if __name__ == "__main__":
    main()
