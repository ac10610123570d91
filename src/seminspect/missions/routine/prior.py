"""``M_H``, the historical map a routine mission plans on: recorded by a mapping traverse of the
historical world, or read from a user's file; and the robot and LiDAR that record it and that
build ``M_C`` during the mission."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, load_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.robot import Robot
from seminspect.sensors import Lidar, render
from seminspect.worlds import World

#: Free-space clearing distance for LiDAR beams without a return [m].
CLEAR_MISSES_M = 10.0
#: Sensing interval while driving [m].
SENSE_EVERY_M = 1.0


LIDAR = Lidar(beams=32, min_elevation_deg=-45.0, max_elevation_deg=45.0,
              horizontal_resolution_deg=0.7, max_range=30.0)  # fmt: skip


def make_robot(world: World, config: RoutineConfig) -> Robot:
    low, high = config.z_limits
    return Robot(
        world,
        "aerial",
        radius=config.robot_radius,
        body_height=1.5,
        v_max=config.speed,
        z_min=low,
        z_max=high,
    )


def sense(robot: Robot, world: World, voxel_map: VoxelMap) -> NDArray[np.float64]:
    """One LiDAR scan from the robot, integrated into ``voxel_map``; returns its points."""
    scan = LIDAR.scan(world, robot.position, robot.quaternion, stamp=robot.time)
    voxel_map.integrate_scan(scan, clear_misses_to=CLEAR_MISSES_M)
    return scan.points


def record_prior(
    world: World, config: RoutineConfig, progress: Callable[[float], None] | None = None
) -> VoxelMap:
    """``M_H``: a traverse down the drift's centre line, a LiDAR scan and three camera frames
    (ahead, left, right) integrated every metre. In a user's world the traverse runs along
    +x from the start to 4 m short of the world's end, stopping where something blocks it."""
    prior = VoxelMap.covering(world, config.map_resolution)
    robot = make_robot(world, config)
    camera = config.camera()
    start = robot.position.copy()
    end_x = float(world.metadata.get("face_x", world.bounds[1][0])) - 4.0
    stops = np.arange(start[0], max(end_x, start[0]) + 1e-9, SENSE_EVERY_M)
    for count, x in enumerate(stops):
        if robot.move_to([x, start[1], start[2]], 0.0).blocked:
            break
        sense(robot, world, prior)
        for yaw in (0.0, math.pi / 2, -math.pi / 2):
            frame = render(world, camera, robot.position, quat_from_yaw(yaw), stride=4)
            prior.integrate_frame(frame, stride=1)
        if progress is not None:
            progress((count + 1) / len(stops))
    return prior


def load_prior(path: str | os.PathLike[str], resolution: float) -> VoxelMap:
    """A historical map from a file: a seminspect map (``.npz``), an OctoMap (``.bt``) or a
    point cloud (``.ply``/``.pcd``: occupied cells, the rest unknown)."""
    source = Path(path)
    suffix = source.suffix.lower()
    if suffix == ".npz":
        return load_map(source)
    if suffix == ".bt":
        from seminspect.mapping.formats.octomap import load_octomap  # noqa: PLC0415 - optional extra

        return load_octomap(source, resolution)
    if suffix in (".ply", ".pcd"):
        from seminspect.mapping.formats.pointfiles import load_point_file  # noqa: PLC0415 - rarely used

        points = load_point_file(source).points
        prior = VoxelMap.empty(points.min(axis=0) - 1.0, points.max(axis=0) + 1.0, resolution)
        cells = prior.world_to_index(points)
        prior.states[tuple(cells.T)] = OCCUPIED
        return prior
    raise FileFormatError(f"{source}: a prior map is .npz, .bt, .ply or .pcd")
