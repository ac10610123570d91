"""Calibrate Γ_thresh of 000 eq (8) for the ORB matcher: ring-closing against other views.

A level ends when a view, taken back within ``d_thresh^I`` of the level's start, matches the
level's first ``N`` = 3 images with ``Γ >= Γ_thresh`` (``perception/similarity.py``). The
threshold must sit above every view that does not close the ring yet is inside that radius, and
below the views that do. For each target of a world this script lays the ring of an inspection
level around it (the target's box grown by the viewing distance, a view every metre, looking at
the centre, at the robot's camera height and pitch), renders it with the mission's realistic
sensor noise, and scores with eq (8):

* **closing** views: back at the start, anywhere from 1 m before the first candidate image to
  the third, 0-0.3 m off the ring and 0-7 degrees off its heading;
* **non-closing** views: ring views 3 m or more from every candidate image yet within
  ``d_thresh^I`` of the start (on the way out and on the way back), each as planned and twice
  displaced like the closing ones.

It prints both distributions per world, the share of each on the wrong side of the threshold,
and the margins: the lowest closing view over the threshold, and the threshold over the highest
non-closing view (ratios; 1 means no margin).

Run: ``.venv/bin/python bench/similarity_calibration.py [--threshold 0.07] [--seed 0]``
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import quat_from_yaw_pitch
from seminspect.missions.xflie.build import camera_pitch
from seminspect.missions.xflie.config import make_config, resolve
from seminspect.perception.similarity import (
    ORB_GAMMA_THRESHOLD,
    ImageFeatures,
    SceneMatcher,
    scene_similarity,
)
from seminspect.platform.simulated import mission_noise
from seminspect.sensors import CameraModel, render
from seminspect.worlds import World
from seminspect.worlds.catalog import generate_world

WORLDS = [("city", "small"), ("collapsed-buildings", "fire-station")]
VIEW_SPACING_M = 1.0
CLOSING_OFFSET_M = 0.3
CLOSING_YAW_DEG = 7.0
FAR_FROM_CANDIDATES_M = 3.0


@dataclass
class Rig:
    """How the mission's robot sees a world: camera, noise, height, pitch, d_view."""

    world: World
    camera: CameraModel
    height: float
    pitch: float
    d_view: float
    d_thresh: float
    classes: tuple[str, ...]
    rng: np.random.Generator

    @classmethod
    def of(cls, world_name: str, scenario: str, seed: int) -> Rig:
        config = resolve(make_config({"world": world_name, "scenario": scenario, "seed": seed}))
        params = config.params
        aerial = config.mode == "aerial"
        return cls(
            world=generate_world(world_name, scenario, seed=seed),
            camera=CameraModel.from_params(params),
            height=config.robot.flight_height if aerial else config.robot.body_height,
            pitch=math.radians(camera_pitch(config)),
            d_view=config.inspection.d_view,
            d_thresh=params.d_thresh_I,
            classes=tuple(config.target_classes),
            rng=make_rng(seed, "bench", "similarity-calibration"),
        )

    def features(self, matcher: SceneMatcher, position, yaw: float) -> ImageFeatures:
        orientation = quat_from_yaw_pitch(yaw, self.pitch)
        noise = mission_noise("realistic", None)
        frame = render(self.world, self.camera, position, orientation, noise=noise, rng=self.rng)
        return matcher.features(frame.intensity)


def ring(centre: np.ndarray, half: np.ndarray, d_view: float, height: float) -> np.ndarray:
    """``(n, 3)`` view positions one metre apart on the ellipse around a box's footprint."""
    a, b = half[0] + d_view, half[1] + d_view
    perimeter = math.pi * (3 * (a + b) - math.sqrt((3 * a + b) * (a + 3 * b)))  # Ramanujan
    angles = np.linspace(0.0, 2 * math.pi, max(12, round(perimeter / VIEW_SPACING_M)), False)
    xy = centre[:2] + np.column_stack([a * np.cos(angles), b * np.sin(angles)])
    return np.column_stack([xy, np.full(len(xy), height)])


def facing(position: np.ndarray, centre: np.ndarray) -> float:
    return math.atan2(centre[1] - position[1], centre[0] - position[0])


def target_scores(rig: Rig, matcher: SceneMatcher, info) -> tuple[list[float], list[float]]:
    """Γ of the closing and of the non-closing views of one target's ring."""
    centre = 0.5 * (info.bbox_min + info.bbox_max)
    views = ring(centre, 0.5 * (info.bbox_max - info.bbox_min), rig.d_view, rig.height)
    start = views[0]
    candidates = [rig.features(matcher, p, facing(p, centre)) for p in views[:3]]

    def gamma(position: np.ndarray, yaw: float) -> float:
        query = rig.features(matcher, position, yaw)
        distance = float(np.linalg.norm(position - start))
        return scene_similarity(matcher, query, candidates, distance, rig.d_thresh)

    def near(point: np.ndarray) -> tuple[np.ndarray, float]:
        """A pose up to 0.3 m off ``point`` towards or away from the target, heading within
        7 degrees of the centre: how far a real view strays from the planned one."""
        towards = (centre - point) * np.array([1.0, 1.0, 0.0])
        offset = rig.rng.uniform(-CLOSING_OFFSET_M, CLOSING_OFFSET_M)
        moved = point + offset * towards / np.linalg.norm(towards)
        yaw = facing(moved, centre) + math.radians(rig.rng.uniform(-1, 1) * CLOSING_YAW_DEG)
        return moved, yaw

    closing = []
    path = np.vstack([views[-1:], views[:3]])  # from the last view round to the third
    for _ in range(12):
        leg = int(rig.rng.integers(len(path) - 1))
        closing.append(gamma(*near(path[leg] + rig.rng.uniform() * (path[leg + 1] - path[leg]))))
    others = []
    for position in views[3:]:
        nearest = min(float(np.linalg.norm(position - c)) for c in views[:3])
        if nearest >= FAR_FROM_CANDIDATES_M and np.linalg.norm(position - start) <= rig.d_thresh:
            others.append(gamma(position, facing(position, centre)))
            others += [gamma(*near(position)) for _ in range(2)]
    return closing, others


def describe(name: str, values: list[float]) -> str:
    v = np.asarray(values)
    return (
        f"{name:12s} n={len(v):3d}  min {v.min():.3f}  p5 {np.percentile(v, 5):.3f}  "
        f"median {np.median(v):.3f}  p95 {np.percentile(v, 95):.3f}  max {v.max():.3f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--threshold", type=float, default=ORB_GAMMA_THRESHOLD)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    matcher = SceneMatcher()
    for world_name, scenario in WORLDS:
        rig = Rig.of(world_name, scenario, args.seed)
        closing, others = [], []
        for info in rig.world.instances_of(*rig.classes):
            near, far = target_scores(rig, matcher, info)
            closing += near
            others += far
        low, high = min(closing), max(others)
        print(f"{world_name} {scenario}, seed {args.seed}: Γ_thresh {args.threshold}")
        print("  " + describe("closing", closing))
        print("  " + describe("non-closing", others))
        print(
            f"  closing views below the threshold: {np.mean(np.less(closing, args.threshold)):.0%}"
            f"; non-closing views at or above it: "
            f"{np.mean(np.greater_equal(others, args.threshold)):.0%}"
        )
        print(
            f"  margins: lowest closing / threshold {low / args.threshold:.2f}, "
            f"threshold / highest non-closing {args.threshold / max(high, 1e-9):.2f}"
        )


if __name__ == "__main__":
    main()
