"""Where the camera of a training frame stands: mostly looking at a target, sometimes anywhere.

A segmentation network learns what the frames show, so the viewpoints decide the dataset: a
target (car, truck or building, its class drawn first so a city's many buildings do not drown
its few cars) seen from 3-15 m (buildings from farther, so they fit partly), from a ground
robot's height or an aerial robot's pitched down, with the heading off the target by up to
most of the half field of view, so targets are often cut by the frame's edge; and a share of
random views, where the network sees streets and walls with no target. Every choice is drawn
from the caller's generator, so a shard's views follow from its seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString, Point

from seminspect.geometry.transforms import Quat, Vec3, quat_from_yaw_pitch
from seminspect.sensors import CameraModel
from seminspect.worlds import InstanceInfo, World

#: The classes a dataset frame looks at (and labels); the order of their dataset ids.
TARGET_CLASSES: tuple[str, ...] = ("car", "truck", "building")
#: Share of frames drawn anywhere, facing anywhere.
RANDOM_VIEW_SHARE = 0.15
#: Share of viewpoints at an aerial robot's height rather than a ground robot's.
AERIAL_SHARE = 0.35
#: Camera heights above the ground (m): a ground robot's and an aerial robot's.
GROUND_HEIGHT = (0.4, 2.0)
AERIAL_HEIGHT = (2.0, 8.0)
#: Distance from a target's footprint to the camera (m), by class.
STANDOFF = {"car": (3.0, 15.0), "truck": (3.0, 15.0), "building": (5.0, 25.0)}
#: The heading may miss the target by up to this share of the half horizontal field of view
#: (the pitch likewise of the vertical one): the target is then cut by the frame's edge.
AIM_JITTER = 0.8


@dataclass(frozen=True)
class Viewpoint:
    """A camera pose and what it was drawn to look at.

    Attributes:
        position: camera position (m).
        orientation: camera orientation ``[x, y, z, w]``.
        target: instance id of the target looked at; 0 for a random view.
    """

    position: Vec3
    orientation: Quat
    target: int


def target_instances(world: World) -> dict[str, list[InstanceInfo]]:
    """The world's targets by class, classes without any left out."""
    found = {name: world.instances_of(name) for name in TARGET_CLASSES}
    return {name: found[name] for name in TARGET_CLASSES if found[name]}


def draw_viewpoint(
    world: World, camera: CameraModel, rng: np.random.Generator, random_view: bool
) -> Viewpoint | None:
    """A viewpoint drawn from ``rng``; None when it stands inside an object or off the world
    (the caller draws again from the same generator, so redraws stay deterministic)."""
    height = _height(rng)
    if random_view:
        low, high = world.bounds[0, :2], world.bounds[1, :2]
        xy = rng.uniform(low, high)
        yaw = rng.uniform(-math.pi, math.pi)
        pitch = rng.uniform(0.0, 0.5) if height > GROUND_HEIGHT[1] else rng.uniform(-0.15, 0.2)
        target = 0
    else:
        info = _pick_target(world, rng)
        xy, yaw, pitch = _aimed_at(info, height + world.ground_z, camera, rng)
        target = info.id
    position = np.array([xy[0], xy[1], world.ground_z + height])
    if not _standable(world, position):
        return None
    return Viewpoint(position, quat_from_yaw_pitch(float(yaw), float(pitch)), target)


def _height(rng: np.random.Generator) -> float:
    band = AERIAL_HEIGHT if rng.uniform() < AERIAL_SHARE else GROUND_HEIGHT
    return float(rng.uniform(*band))


def _pick_target(world: World, rng: np.random.Generator) -> InstanceInfo:
    """A target: its class first (uniform over the classes present), then one of that class."""
    by_class = target_instances(world)
    classes = list(by_class)
    chosen = by_class[classes[int(rng.integers(len(classes)))]]
    return chosen[int(rng.integers(len(chosen)))]


def _aimed_at(
    info: InstanceInfo, camera_z: float, camera: CameraModel, rng: np.random.Generator
) -> tuple[np.ndarray, float, float]:
    """Camera ``xy``, yaw and pitch looking at ``info`` from a standoff of its class."""
    bearing = rng.uniform(-math.pi, math.pi)
    direction = np.array([math.cos(bearing), math.sin(bearing)])
    standoff = rng.uniform(*STANDOFF.get(info.class_name, STANDOFF["car"]))
    centre = np.asarray(info.centroid[:2], dtype=float)
    xy = centre + direction * (_reach(info, centre, direction) + standoff)
    aim_z = rng.uniform(info.bbox_min[2], info.bbox_max[2])
    distance = float(np.linalg.norm(xy - centre))
    yaw = bearing + math.pi + rng.uniform(-1, 1) * AIM_JITTER * math.radians(camera.hfov_deg) / 2
    pitch = math.atan2(camera_z - aim_z, distance)
    pitch += rng.uniform(-1, 1) * AIM_JITTER * math.radians(camera.vfov_deg) / 2
    return xy, yaw, float(np.clip(pitch, -0.6, 1.3))


def _reach(info: InstanceInfo, centre: np.ndarray, direction: np.ndarray) -> float:
    """How far the footprint reaches from ``centre`` along ``direction`` (m)."""
    span = float(np.linalg.norm(info.bbox_max[:2] - info.bbox_min[:2])) + 1.0
    ray = LineString([tuple(centre), tuple(centre + direction * span)])
    return float(ray.intersection(info.footprint).length)


def _standable(world: World, position: np.ndarray) -> bool:
    """Whether the camera is on the world and outside every object's box."""
    low, high = world.bounds[0, :2], world.bounds[1, :2]
    if np.any(position[:2] < low) or np.any(position[:2] > high):
        return False
    point = Point(float(position[0]), float(position[1]))
    for info in world.instances.values():
        below_top = position[2] <= info.bbox_max[2] + 0.1
        if below_top and info.footprint.buffer(0.2).contains(point):
            return False
    return True
