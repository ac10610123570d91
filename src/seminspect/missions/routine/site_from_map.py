"""A routine site built from a map file's own voxels (``routine inspect --world MAP.bt``).

The historical and the current world are one world whose surfaces bound the map's occupied
voxels (:func:`~seminspect.worlds.voxels.world_from_voxels`, at the file's own cell size), so
the mission drives in the mapped site and is checked against it; ``M_H`` is the same file
painted onto the mission's grid. The robot starts in the largest free component of ``M_H``'s
known-free cells that keep the robot's radius and the planning margin from every occupied cell,
at its take-off height or above and within its height limits: at the cell farthest from the
occupied cells of its own height. A map with no such space, or too little of it to fly a view
tour in, is refused with the reason.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.executive import PLANNING_MARGIN_M
from seminspect.missions.routine.prior import BODY_HEIGHT_M
from seminspect.planning.free_space import FreeSpace
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.map_files import MAP_SUFFIXES, read_map_file
from seminspect.worlds.routine_sites import SitePair
from seminspect.worlds.voxels import world_from_voxels

#: Least free volume a map site must offer the robot [m³]: room for a few views at d_view.
MIN_FREE_M3 = 4.0
SITE_KIND = "map"
#: Distance-transform sampling that makes vertical steps so long that only a cell's own layer
#: counts.
_LAYERS_ONLY = (1.0, 1.0, 1e6)


def is_map_file(name: str | os.PathLike[str]) -> bool:
    """Whether ``--world`` names a map file rather than a built-in site."""
    return Path(name).suffix.lower() in MAP_SUFFIXES


def site_from_map(path: str | os.PathLike[str], config: RoutineConfig) -> SitePair:
    """The site of a map file, as the module docstring says; a map that cannot host a routine
    run is an :class:`InvalidInputError` naming the file and the reason."""
    source = Path(path)
    voxels = read_map_file(source)  # the map's own cells make the world
    prior = (  # M_H's grid: where the start is chosen
        voxels
        if math.isclose(voxels.resolution, config.map_resolution, rel_tol=1e-6)
        else read_map_file(source, config.map_resolution)
    )
    # the robot takes off BODY_HEIGHT_M above the world's start point
    start = robot_start(prior, config, source, lowest=float(voxels.origin[2]) + BODY_HEIGHT_M)
    start[2] -= BODY_HEIGHT_M
    occupied = voxels.states == OCCUPIED
    world = world_from_voxels(
        occupied,
        voxels.origin,
        voxels.resolution,
        name=source.stem,
        start_position=start,
        metadata={"source": str(source)},
    )
    change = {"kind": SITE_KIND, "map": str(source)}
    return SitePair(source.stem, 0, world, world, change)


def robot_start(
    prior: VoxelMap, config: RoutineConfig, source: Path, lowest: float
) -> NDArray[np.float64]:
    """The free cell of the largest free component farthest (horizontally) from every occupied
    cell (of those, the nearest the component's middle), at the robot's heights and no lower
    than ``lowest``."""
    clearance = config.robot_radius + PLANNING_MARGIN_M
    grid = CostGrid.build(prior, CostModel(clearance, risk_radius=0.0))
    low, high = max(config.z_limits[0], lowest), config.z_limits[1]
    space = FreeSpace(grid, z_band=(low, high))
    if space.count == 0:
        raise InvalidInputError(
            f"{source}: no known-free space {clearance:g} m clear of the map's occupied cells "
            f"between z {low:g} and {high:g} m; a routine site needs free space the map's "
            "sensor saw, at the robot's heights"
        )
    volume = space.volume_m3(1)
    if volume < MIN_FREE_M3:
        raise InvalidInputError(
            f"{source}: its largest free space is {volume:.1f} m³, less than the "
            f"{MIN_FREE_M3:g} m³ a routine run needs to fly its views"
        )
    cells = space.cells[space.cell_labels == 1]
    # horizontal distance at the cell's own height: floor and ceiling would tie every cell
    distance = ndimage.distance_transform_edt(prior.states != OCCUPIED, sampling=_LAYERS_ONLY)
    clear = distance[tuple(cells.T)]
    spread = np.linalg.norm(cells - cells.mean(axis=0), axis=1)
    best = cells[np.lexsort((spread, -clear))[0]]  # ties: the one nearest the middle
    return prior.index_to_world(best[None])[0]
