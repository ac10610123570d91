"""A world made from a volumetric map's occupied voxels (an OctoMap of a real site).

Worlds cannot read map files (mapping ranks above them), so this module takes arrays: a
boolean occupancy grid, its origin and cell size. The surface is the boundary of the occupied
cells, extracted with marching cubes (scikit-image) at the half-way level of the 0/1 grid, so
a flat wall's surface lies on the faces of its cells. Every face is background (no objects, no
ground class): the site is geometry a mission senses and must not collide with.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from skimage.measure import marching_cubes

from seminspect.core.errors import InvalidInputError
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.world import BACKGROUND, World


def voxel_surface(
    occupied: NDArray[np.bool_], origin: ArrayLike, resolution: float
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Vertices (world metres) and triangles of the boundary of the occupied cells."""
    if occupied.ndim != 3 or not occupied.any():
        raise InvalidInputError("a world from voxels needs a 3D grid with occupied cells")
    if not (math.isfinite(resolution) and resolution > 0):
        raise InvalidInputError(f"voxel size must be > 0, got {resolution!r}")
    padded = np.pad(occupied, 1).astype(np.float32)  # closes surfaces at the grid's sides
    vertices, faces, _, _ = marching_cubes(padded, 0.5, allow_degenerate=False)
    # padded index i is cell i - 1, whose centre lies at origin + (i - 1 + 0.5) * resolution
    points = np.asarray(origin, dtype=np.float64) + (vertices.astype(np.float64) - 0.5) * resolution
    return points, faces.astype(np.int64)


def world_from_voxels(
    occupied: NDArray[np.bool_],
    origin: ArrayLike,
    resolution: float,
    *,
    name: str,
    start_position: ArrayLike,
    start_yaw: float = 0.0,
    metadata: dict[str, object] | None = None,
) -> World:
    """A :class:`World` whose surfaces bound ``occupied`` and whose bounds are the grid's box."""
    vertices, faces = voxel_surface(occupied, origin, resolution)
    builder = WorldBuilder(name)
    builder.add_faces(vertices, faces, BACKGROUND)
    low = np.asarray(origin, dtype=np.float64)
    high = low + resolution * np.asarray(occupied.shape, dtype=np.float64)
    info = {"generator": "voxels", "voxel_size_m": float(resolution), "ground_z": float(low[2])}
    return builder.build(
        np.stack([low, high]), start_position, start_yaw, {**info, **(metadata or {})}
    )
