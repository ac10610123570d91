"""Building an xFLIE mission: the world, the simulated robot at its start, the empty map and the
executive (or the frontier explorer), from a resolved configuration."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

from seminspect.core.threads import sensor_threads
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie import MissionProgress, XFlie
from seminspect.missions.xflie.config import MissionConfig, ResolvedMissionConfig, inspects
from seminspect.missions.xflie.features import warn_about_feature_labels
from seminspect.missions.xflie.frontier import FrontierMission
from seminspect.platform.simulated import SimulatedPlatform, mission_noise
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Detector
from seminspect.worlds import World, open_world
from seminspect.worlds.catalog import is_world_path
from seminspect.worlds.checks import warn_if_no_targets


def run_name(config: MissionConfig) -> str:
    """``city-small-seed0``; a user world is named by its file or folder."""
    world = Path(config.world).stem if is_world_path(config.world) else config.world
    scenario = f"-{config.scenario}" if config.scenario else ""
    return f"{world}{scenario}-seed{config.seed}"


def mission_map(world: World, config: ResolvedMissionConfig) -> VoxelMap:
    """The robot's empty occupancy map over ``world``; with a second core its rays are walked
    into it on a worker thread while the mission goes on (the same map, see
    :class:`~seminspect.mapping.voxel.VoxelMap`)."""
    occupancy = VoxelMap.covering(world, config.map_resolution)
    occupancy.background = sensor_threads() > 1
    return occupancy


def build_mission(
    config: ResolvedMissionConfig,
    run: RunDirectory | None,
    progress: Callable[[MissionProgress], None] | None = None,
    world: World | None = None,
    detector: Detector | None = None,
) -> tuple[XFlie, World]:
    """The world (made from ``config`` unless given), the robot in it and the executive; the
    robot sees through ``detector`` (default: the simulator's labels with the fault model)."""
    world = world or open_world(config.world, config.scenario, seed=config.seed)
    warn_if_no_targets(world, config.target_classes)
    if inspects(config.planner):
        warn_about_feature_labels(world, config.target_classes, config.feature_labels)
    platform, ground_z = build_platform(config, world, detector=detector)
    occupancy = mission_map(world, config)
    executive = XFlie if inspects(config.planner) else FrontierMission
    mission = executive(config, platform, occupancy, ground_z=ground_z, run=run, progress=progress)
    return mission, world


def build_platform(
    config: ResolvedMissionConfig,
    world: World,
    name: str | None = None,
    detector: Detector | None = None,
) -> tuple[SimulatedPlatform, float]:
    """The simulated robot at the world's start, and the height of the ground it stands on;
    a ``name`` gives a robot of a team noise streams of its own."""
    params = config.params
    # Ground robots carry the camera at body height; aerial ones start at Level-0's height.
    aerial = config.mode == "aerial"
    start_height = config.robot.flight_height if aerial else config.robot.body_height
    platform = SimulatedPlatform(
        world,
        params,
        mode=config.mode,
        noise=mission_noise(config.noise, config.odometry_drift_per_m),
        seed=config.seed,
        radius=config.robot.radius,
        speed=config.robot.speed,
        yaw_rate=config.robot.yaw_rate,
        body_height=start_height,
        camera_pitch=math.radians(camera_pitch(config)),
        name=name,
        threads=sensor_threads(),
        detector=detector,
    )
    return platform, float(platform.position[2] - start_height)


def camera_pitch(config: MissionConfig) -> float:
    """Camera tilt in degrees: the configured one, or 20 for aerial and 0 for ground robots."""
    if config.robot.camera_pitch_deg is not None:
        return config.robot.camera_pitch_deg
    return 20.0 if config.mode == "aerial" else 0.0
