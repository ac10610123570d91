"""Tiny hand-made occupancy maps with known frontiers, shared by the planning and mission tests."""

from __future__ import annotations

from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap


def corridor_map() -> VoxelMap:
    """A 20 m x 10 m map: the west half explored, a wall along y = 8 m, the east half unknown."""
    grid = VoxelMap.empty([0, 0, -0.25], [20, 10, 2.25], 0.5)
    grid.states[:20, :, :] = FREE
    grid.states[:, 16, :] = OCCUPIED  # the wall, unknown beyond it
    grid.states[:, 17:, :] = UNKNOWN
    return grid
