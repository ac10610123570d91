"""Map files a planner can read: a seminspect map (``.npz``), an OctoMap (``.bt``, extra
``octomap``) or a point cloud (``.ply``/``.pcd``: occupied cells, the rest unknown).

Used wherever a map is taken from a user: ``seminspect plan`` and the priors of routine
inspection (:mod:`~seminspect.missions.routine.prior`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, load_map

MAP_SUFFIXES = (".npz", ".bt", ".ply", ".pcd")
#: A point cloud's box reaches this far past its points [m], so its surfaces have a free side.
CLOUD_MARGIN_M = 1.0
#: Cell size of a point cloud read without a resolution [m].
DEFAULT_CLOUD_RESOLUTION = 0.1


def read_map_file(path: str | os.PathLike[str], resolution: float | None = None) -> VoxelMap:
    """The map in ``path`` at ``resolution`` (default: the file's own; 0.1 m for a cloud).

    An OctoMap is painted onto the grid, a cloud rasterised; a ``.npz`` map is coarsened to a
    coarser ``resolution`` (a finer one cannot be made up and is refused).
    """
    source = Path(path)
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise InvalidInputError(f"resolution must be a number > 0, got {resolution!r}")
    suffix = source.suffix.lower()
    if suffix == ".npz":
        return _npz_map(source, resolution)
    if suffix == ".bt":
        from seminspect.mapping.formats.octomap import load_octomap  # noqa: PLC0415 - optional extra

        return load_octomap(source, resolution)
    if suffix in (".ply", ".pcd"):
        return cloud_map(source, DEFAULT_CLOUD_RESOLUTION if resolution is None else resolution)
    raise FileFormatError(f"{source}: a map file is {', '.join(MAP_SUFFIXES)}")


def cloud_map(source: Path, resolution: float) -> VoxelMap:
    """The occupied cells of a point cloud; every other cell of its box is unknown."""
    from seminspect.mapping.formats.pointfiles import load_point_file  # noqa: PLC0415 - rarely used

    points = load_point_file(source).points
    if not len(points):
        raise FileFormatError(f"{source}: the point cloud has no points")
    grid = VoxelMap.empty(
        points.min(axis=0) - CLOUD_MARGIN_M, points.max(axis=0) + CLOUD_MARGIN_M, resolution
    )
    cells = grid.world_to_index(points)
    grid.states[tuple(cells.T)] = OCCUPIED
    return grid


def _npz_map(source: Path, resolution: float | None) -> VoxelMap:
    voxel_map = load_map(source)
    if resolution is None or math.isclose(resolution, voxel_map.resolution, rel_tol=1e-6):
        return voxel_map
    if resolution < voxel_map.resolution:
        raise InvalidInputError(
            f"{source}: its cells are {voxel_map.resolution:g} m; a finer resolution "
            f"({resolution:g} m) cannot be made from it: give {voxel_map.resolution:g} m or more"
        )
    return voxel_map.coarsened(resolution)
