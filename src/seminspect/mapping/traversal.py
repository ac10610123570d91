"""Compiled ray traversal through a voxel grid (Amanatides and Woo, "A fast voxel traversal
algorithm for ray tracing", 1987).

Each ray is clipped to the grid, then walked cell by cell: every cell it crosses becomes free,
the cell holding its end point becomes occupied if the ray hit a surface there. Occupied cells
stay occupied (a grazing ray never erases a surface another ray saw), which keeps the map
conservative for planning.
"""

from __future__ import annotations

import math

import numba
import numpy as np

FREE = np.uint8(1)
OCCUPIED = np.uint8(2)


@numba.njit(cache=True)
def _clip(o: np.ndarray, d: np.ndarray, shape: tuple) -> tuple[float, float]:
    """Parameter interval [t0, t1] within [0, 1] of ``o + t d`` inside the grid box."""
    t0, t1 = 0.0, 1.0
    for k in range(3):
        if d[k] == 0.0:
            if o[k] < 0.0 or o[k] >= shape[k]:
                return 1.0, 0.0
            continue
        ta = (0.0 - o[k]) / d[k]
        tb = (shape[k] - o[k]) / d[k]
        t0 = max(t0, min(ta, tb))
        t1 = min(t1, max(ta, tb))
    return t0, t1


@numba.njit(cache=True)
def _mark(states: np.ndarray, i: int, j: int, k: int, value: np.uint8) -> None:
    """Set a cell, except that nothing overwrites OCCUPIED."""
    if states[i, j, k] != OCCUPIED:
        states[i, j, k] = value


@numba.njit(cache=True)
def _start_axis(o: float, d: float, cell: int) -> tuple[int, float, float]:
    """Step direction, parameter of the first cell boundary and parameter per cell on one axis."""
    if d > 0:
        return 1, (cell + 1 - o) / d, 1.0 / d
    if d < 0:
        return -1, (cell - o) / d, -1.0 / d
    return 0, np.inf, np.inf


@numba.njit(cache=True)
def _walk(states: np.ndarray, o: np.ndarray, d: np.ndarray, hit: bool) -> None:
    """Free every cell from the grid entry of ``o + t d`` to its end; occupy the end on a hit."""
    shape = states.shape
    t0, t1 = _clip(o, d, shape)
    if t0 > t1:
        return
    cell = np.empty(3, dtype=np.int64)
    last = np.empty(3, dtype=np.int64)
    step = np.empty(3, dtype=np.int64)
    t_max = np.empty(3)
    t_delta = np.empty(3)
    for k in range(3):
        cell[k] = min(max(math.floor(o[k] + t0 * d[k]), 0), shape[k] - 1)
        last[k] = min(max(math.floor(o[k] + t1 * d[k]), 0), shape[k] - 1)
        step[k], t_max[k], t_delta[k] = _start_axis(o[k], d[k], cell[k])
    occupy_end = hit
    for k in range(3):
        occupy_end = occupy_end and 0.0 <= o[k] + d[k] < shape[k]
    for _ in range(shape[0] + shape[1] + shape[2] + 3):
        if cell[0] == last[0] and cell[1] == last[1] and cell[2] == last[2]:
            break
        _mark(states, cell[0], cell[1], cell[2], FREE)
        axis = 0
        if t_max[1] < t_max[axis]:
            axis = 1
        if t_max[2] < t_max[axis]:
            axis = 2
        if t_max[axis] > t1:
            break
        cell[axis] += step[axis]
        if cell[axis] < 0 or cell[axis] >= shape[axis]:
            break
        t_max[axis] += t_delta[axis]
    # The end cell is set even when rounding let the walk slip past it along an edge or corner.
    _mark(states, last[0], last[1], last[2], OCCUPIED if occupy_end else FREE)


@numba.njit(cache=True)
def integrate_rays_kernel(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    states: np.ndarray,
    grid_origin: np.ndarray,
    resolution: float,
    origins: np.ndarray,
    ends: np.ndarray,
    hit: np.ndarray,
) -> None:
    """Walk every ray ``origins[r or 0] -> ends[r]`` (world metres) through ``states``."""
    o = np.empty(3)
    d = np.empty(3)
    shared = origins.shape[0] == 1
    for r in range(ends.shape[0]):
        src = origins[0] if shared else origins[r]
        for k in range(3):
            o[k] = (src[k] - grid_origin[k]) / resolution
            d[k] = (ends[r, k] - grid_origin[k]) / resolution - o[k]
        _walk(states, o, d, hit[r])
