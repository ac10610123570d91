"""``M_H``, the historical map a routine mission plans on: recorded by a mapping traverse of the
historical world, or read from a user's file; and the robot and LiDAR that record it and that
build ``M_C`` during the mission.

A prior is checked against the site before any work (:func:`check_prior`): a map of another
place or at another resolution would otherwise plan views on the wrong surfaces and report
the difference as change. :func:`save_prior` records the world a prior was mapped in (its
name, the frame of its coordinates, and its bounds) beside the map; priors without those
fields (other programs' maps, older files) are checked by extent and resolution only.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.mapping.voxel import VoxelMap, load_map, save_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.tasks import describe_box
from seminspect.planning.map_files import read_map_file
from seminspect.robot import Robot
from seminspect.sensors import Lidar, render
from seminspect.worlds import World
from seminspect.worlds.routine_sites import SitePair

#: Free-space clearing distance for LiDAR beams without a return [m].
CLEAR_MISSES_M = 10.0
#: Sensing interval while driving [m].
SENSE_EVERY_M = 1.0
#: How far each side of a prior's box may lie from the site's bounds [m]: a point-cloud prior
#: reaches 1 m past its points, and a coarse OctoMap leaf past the surface it holds.
EXTENT_MARGIN_M = 2.0
#: Take-off height of the routine robot above the world's start point [m].
BODY_HEIGHT_M = 1.5
#: The arrays :func:`save_prior` adds to a voxel map file (``load_map`` ignores them).
SITE_FIELDS = ("site_frame", "site_bounds")


LIDAR = Lidar(beams=32, min_elevation_deg=-45.0, max_elevation_deg=45.0,
              horizontal_resolution_deg=0.7, max_range=30.0)  # fmt: skip


def make_robot(world: World, config: RoutineConfig) -> Robot:
    low, high = config.z_limits
    return Robot(
        world,
        "aerial",
        radius=config.robot_radius,
        body_height=BODY_HEIGHT_M,
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


def save_prior(path: str | os.PathLike[str], prior: VoxelMap, historical: World) -> Path:
    """Write ``M_H`` as a voxel map file (atomically) that also records the world it was
    mapped in: ``site_frame`` (the world's name, whose coordinates the map uses) and
    ``site_bounds``, so that :func:`load_prior` can tell it from a map of another site."""
    return save_map(
        path,
        prior,
        site_frame=np.array(historical.name),
        site_bounds=np.asarray(historical.bounds, dtype=np.float64),
    )


def load_prior(
    path: str | os.PathLike[str], resolution: float, site: SitePair | None = None
) -> VoxelMap:
    """A historical map from a file: a seminspect map (``.npz``), an OctoMap (``.bt``) or a
    point cloud (``.ply``/``.pcd``: occupied cells, the rest unknown). With ``site``, a map
    that does not fit it is refused (:func:`check_prior`)."""
    prior, recorded = _read_prior(Path(path), resolution)
    if site is not None:
        check_prior(prior, site, resolution, path, recorded)
    return prior


def check_prior(
    prior: VoxelMap,
    site: SitePair,
    resolution: float,
    source: str | os.PathLike[str],
    recorded: dict[str, np.ndarray] | None = None,
) -> None:
    """Refuse a prior that does not fit the site, in one line naming ``source`` and every
    difference: another resolution than the mission maps at, another recorded world, or a box
    whose sides lie more than :data:`EXTENT_MARGIN_M` from the site's bounds."""
    world = site.historical
    differences = []
    if not math.isclose(prior.resolution, resolution, rel_tol=1e-6):
        differences.append(
            f"its cells are {prior.resolution:g} m, the mission maps at {resolution:g} m"
        )
    frame = None if recorded is None else recorded.get("site_frame")
    if frame is not None and str(frame) != world.name:
        differences.append(f"it was mapped in world {str(frame)!r}, the site is {world.name!r}")
    site_box = np.asarray(world.bounds, dtype=np.float64)
    prior_box = np.stack([prior.origin, prior.upper])
    if np.abs(prior_box - site_box).max() > EXTENT_MARGIN_M:
        differences.append(
            f"it covers {describe_box(*prior_box)}, the site {describe_box(*site_box)} "
            f"(sides more than {EXTENT_MARGIN_M:g} m apart)"
        )
    if differences:
        raise InvalidInputError(
            f"{source}: M_H does not fit the site: {'; '.join(differences)}; {_fix(source)}"
        )


def _fix(source: str | os.PathLike[str]) -> str:
    """What to do about a prior that does not fit: a map of another site can be a site."""
    hint = "record M_H of this site with 'seminspect routine map'"
    if Path(source).suffix.lower() == ".bt":
        return f"{hint}, or inspect the map's own site with --world {source}"
    return hint


def _read_prior(source: Path, resolution: float) -> tuple[VoxelMap, dict[str, np.ndarray]]:
    """The map of a prior file and the site fields it records (none but in ``.npz`` files)."""
    suffix = source.suffix.lower()
    if suffix == ".npz":
        prior = load_map(source)
        return prior, _site_fields(source, prior)
    return _foreign_prior(source, suffix, resolution), {}


def _site_fields(source: Path, prior: VoxelMap) -> dict[str, np.ndarray]:
    """The site fields of a map file, checked against its own grid (a file whose states do not
    span its recorded bounds was cut or altered: a ``FileFormatError``)."""
    with np.load(source, allow_pickle=False) as archive:
        recorded = {key: archive[key] for key in SITE_FIELDS if key in archive.files}
    if not recorded:
        return recorded  # not recorded by save_prior
    frame, bounds = recorded.get("site_frame"), recorded.get("site_bounds")
    if frame is None or frame.shape != () or frame.dtype.kind != "U":
        raise FileFormatError(f"{source}: site_frame must be the name of the world mapped")
    if bounds is None or bounds.shape != (2, 3) or not np.all(np.isfinite(bounds)):
        raise FileFormatError(f"{source}: site_bounds must be a finite (2, 3) box")
    expected = tuple(int(n) for n in np.ceil((bounds[1] - prior.origin) / prior.resolution - 1e-9))
    if prior.shape != expected:
        raise FileFormatError(
            f"{source}: voxel states have shape {prior.shape}, its origin, resolution and "
            f"site bounds need {expected}; record M_H again with 'seminspect routine map'"
        )
    return recorded


def _foreign_prior(source: Path, suffix: str, resolution: float) -> VoxelMap:
    if suffix not in (".bt", ".ply", ".pcd"):
        raise FileFormatError(f"{source}: a prior map is .npz, .bt, .ply or .pcd")
    return read_map_file(source, resolution)
