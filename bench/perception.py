"""Perception speeds on frames of the city's vehicles, against whole-frame forms in the same run.

Frames: three views of every vehicle of the city (medium, seed 0: the default mission's
world), the 640 x 480 camera 4-15 m away, 1 m up, looking at the vehicle, with the
``realistic`` noise a mission uses. On every frame, interleaved so that both forms of a step
see the same machine load, it times:

* ``detect``: segmentation of the vehicles (``instance``) and of their parts (``part``), each
  mask worked on in its box grown by the bleed, against every step on whole-frame masks
  (``whole_frame_detect`` below);
* ``detection_points``: a detection's points after the mission's 2-pixel erosion, eroded in
  the mask's box and placed from its pixel indices by a compiled loop, against whole-frame
  erosion and the numpy back-projection of the whole mask;
* clustering: ``geometry.clustering.dbscan_labels`` against scikit-learn's ``DBSCAN`` on each
  detection's points (at most ``CLUSTER_POINTS``, sampled as localisation samples them).

Each pair is checked to give the same result; the figures are milliseconds per call (median
and total over the calls) and the total of the whole-frame form over the new one.

Run: ``PYTHONPATH=src .venv/bin/python bench/perception.py [--scenario medium] [--views 3]``
"""

from __future__ import annotations

import argparse
import math
import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation
from sklearn.cluster import DBSCAN

from seminspect.core.rng import make_rng
from seminspect.core.threads import rotate_rows
from seminspect.geometry.clustering import dbscan_labels
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.perception.detections import MAX_MASK_POINTS, detection_points
from seminspect.perception.localisation import CLUSTER_POINTS, erode_mask
from seminspect.sensors import CameraModel, Frame, render
from seminspect.sensors.noise import make_noise
from seminspect.sensors.segmentation import Detection, _distort, _keys, detect
from seminspect.worlds import World, generate_world

VEHICLES = ("car", "truck")  # MissionConfig.target_classes by default
EROSION_PX = 2  # MissionConfig.mask_erosion_px


def vehicle_frames(world: World, views: int) -> list[Frame]:
    """``views`` frames of every vehicle, each from a free point 4-15 m away."""
    rng = np.random.default_rng(0)
    noise = make_noise({}, base="realistic")
    frames = []
    for info in (i for i in world.instances.values() if i.class_name in VEHICLES):
        for _ in range(20 * views):
            heading = rng.uniform(0, 2 * math.pi)
            back = rng.uniform(4, 15) * np.array([math.cos(heading), math.sin(heading)])
            eye = np.array([*(info.centroid[:2] - back), 1.0])
            if world.is_free(eye[None], 0.4, "ground")[0]:
                frame_rng = make_rng(len(frames), "bench-frame")
                view = quat_from_yaw(heading)
                frames.append(render(world, CameraModel(), eye, view, noise=noise, rng=frame_rng))
                if len(frames) % views == 0:
                    break
    return frames


def whole_frame_detect(frame: Frame, world: World, level: str, noise, rng) -> list[int]:
    """``detect``'s steps on whole-frame masks (the form before masks were cut to their box);
    the areas of the masks it keeps."""
    key, candidates, _ = _keys(frame, world, level, VEHICLES, None)
    background = frame.instance == 0
    areas = []
    for value, _label, _inst in candidates:
        mask = _distort(key == value, background, noise)
        area = int(mask.sum())
        if area < noise.min_mask_area_px:
            continue
        values = frame.depth[mask]
        values = values[np.isfinite(values)]
        depth = float(np.median(values)) if len(values) else math.inf
        if rng.random() < noise.miss_chance(depth, area):
            continue
        if noise.score_sigma:
            rng.normal(noise.score_mean, noise.score_sigma)
        mask.any(axis=1), mask.any(axis=0)  # the box
        areas.append(area)
    return areas


def whole_frame_points(frame: Frame, detection: Detection) -> np.ndarray:
    mask = erode_mask(detection.mask, EROSION_PX)
    step = math.ceil(math.sqrt(detection.area_px / MAX_MASK_POINTS))
    if step > 1:
        grid = np.zeros_like(mask)
        grid[::step, ::step] = True
        mask = mask & grid
    flat = np.flatnonzero(mask & np.isfinite(frame.depth))
    directions, cosine = frame.camera.rays
    body = directions[flat] * (frame.depth.ravel()[flat] / cosine[flat])[:, None]
    rotation = Rotation.from_quat(frame.odometry_orientation).as_matrix()
    return rotate_rows(body, rotation) + frame.odometry_position


def sampled(points: np.ndarray) -> np.ndarray:
    return points[:: len(points) // CLUSTER_POINTS + 1] if len(points) > CLUSTER_POINTS else points


def measure(world: World, frames: list[Frame]) -> dict[str, list[float]]:
    noise = make_noise({}, base="realistic")
    times: dict[str, list[float]] = defaultdict(list)

    def timed(name: str, call: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        result = call(*args, **kwargs)
        times[name].append(time.perf_counter() - start)
        return result

    for index, frame in enumerate(frames):
        kept = {}
        for level in ("part", "instance"):
            found = timed(
                f"detect {level}",
                detect,
                frame,
                world,
                level,
                classes=VEHICLES,
                noise=noise,
                rng=make_rng(index, "b"),
            )
            areas = timed(
                f"detect {level}, whole frame",
                whole_frame_detect,
                frame,
                world,
                level,
                noise,
                make_rng(index, "b"),
            )
            kept[level] = [d for d in found if not d.is_false_positive]
            assert [d.area_px for d in kept[level]] == areas
        for detection in kept["instance"]:
            points = timed("detection_points", detection_points, frame, detection, EROSION_PX)
            reference = timed("detection_points, whole frame", whole_frame_points, frame, detection)
            np.testing.assert_array_equal(points, reference)
            cloud = sampled(points)
            if len(cloud) < 5:
                continue
            labels = timed("dbscan_labels", dbscan_labels, cloud, 0.5, 5)
            expected = timed(
                "DBSCAN, scikit-learn", DBSCAN(eps=0.5, min_samples=5).fit_predict, cloud
            )
            np.testing.assert_array_equal(labels, expected)
    return times


def report(times: dict[str, list[float]]) -> None:
    print(f"{'step':34s} {'calls':>6s} {'median ms':>10s} {'total ms':>10s}")
    for name, values in times.items():
        print(
            f"{name:34s} {len(values):6d} {np.median(values) * 1e3:10.3f} {sum(values) * 1e3:10.1f}"
        )
    for new, old in [
        ("detect instance", "detect instance, whole frame"),
        ("detect part", "detect part, whole frame"),
        ("detection_points", "detection_points, whole frame"),
        ("dbscan_labels", "DBSCAN, scikit-learn"),
    ]:
        print(f"{new}: {sum(times[old]) / sum(times[new]):.1f}x faster than {old}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="medium", help="city scenario")
    parser.add_argument("--views", type=int, default=3, help="frames of each vehicle")
    args = parser.parse_args()
    world = generate_world("city", args.scenario, seed=0)
    frames = vehicle_frames(world, args.views)
    measure(world, frames[:2])  # compiles the kernels and warms the caches
    print(f"{len(frames)} frames of vehicles in the city ({args.scenario}, seed 0)")
    report(measure(world, frames))


if __name__ == "__main__":
    main()
