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


@numba.njit(cache=True, inline="always")
def _clip_axis(t0: float, t1: float, o: float, d: float, size: int) -> tuple[float, float]:
    """Narrow ``[t0, t1]`` to where ``o + t d`` lies within ``[0, size)`` on one axis."""
    if d == 0.0:
        if o < 0.0 or o >= size:
            return 1.0, 0.0
        return t0, t1
    ta = (0.0 - o) / d
    tb = (size - o) / d
    return max(t0, min(ta, tb)), min(t1, max(ta, tb))


@numba.njit(cache=True, inline="always")
def _mark(states: np.ndarray, i: int, j: int, k: int, value: np.uint8) -> None:
    """Set a cell, except that nothing overwrites OCCUPIED."""
    if states[i, j, k] != OCCUPIED:
        states[i, j, k] = value


@numba.njit(cache=True, inline="always")
def _start_axis(o: float, d: float, cell: int) -> tuple[int, float, float]:
    """Step direction, parameter of the first cell boundary and parameter per cell on one axis."""
    if d > 0:
        return 1, (cell + 1 - o) / d, 1.0 / d
    if d < 0:
        return -1, (cell - o) / d, -1.0 / d
    return 0, np.inf, np.inf


@numba.njit(cache=True, inline="always")
def _cell(x: float, size: int) -> int:
    """The cell index of grid coordinate ``x``, clamped into ``[0, size)``."""
    return min(max(math.floor(x), 0), size - 1)


@numba.njit(cache=True, inline="always")
def _advance(  # noqa: PLR0917 - inlined into the walk
    cell: int, boundary: float, per_cell: float, step: int, size: int, t1: float
) -> tuple[int, float, bool]:
    """Step one cell along an axis; False once the ray ends or leaves the grid first."""
    if boundary > t1:
        return cell, boundary, False
    cell += step
    if cell < 0 or cell >= size:
        return cell, boundary, False
    return cell, boundary + per_cell, True


@numba.njit(cache=True)
def _walk(  # noqa: PLR0917 - scalars keep the per-ray walk free of allocations
    states: np.ndarray,
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    hit: bool,
) -> None:
    """Free every cell from the grid entry of ``o + t d`` to its end; occupy the end on a hit.

    Three scalars per axis rather than small arrays: the walk runs once per ray, and
    allocating its state dominated short rays.
    """
    nx, ny, nz = states.shape
    t0, t1 = _clip_axis(0.0, 1.0, ox, dx, nx)
    t0, t1 = _clip_axis(t0, t1, oy, dy, ny)
    t0, t1 = _clip_axis(t0, t1, oz, dz, nz)
    if t0 > t1:
        return
    i, j, k = _cell(ox + t0 * dx, nx), _cell(oy + t0 * dy, ny), _cell(oz + t0 * dz, nz)
    li, lj, lk = _cell(ox + t1 * dx, nx), _cell(oy + t1 * dy, ny), _cell(oz + t1 * dz, nz)
    si, mi, di = _start_axis(ox, dx, i)
    sj, mj, dj = _start_axis(oy, dy, j)
    sk, mk, dk = _start_axis(oz, dz, k)
    occupy_end = hit and 0.0 <= ox + dx < nx and 0.0 <= oy + dy < ny and 0.0 <= oz + dz < nz
    for _ in range(nx + ny + nz + 3):
        if i == li and j == lj and k == lk:
            break
        _mark(states, i, j, k, FREE)
        # The axis whose next boundary comes first; ties go to the lower axis.
        axis = (2 if mk < mj else 1) if mj < mi else (2 if mk < mi else 0)
        if axis == 0:
            i, mi, inside = _advance(i, mi, di, si, nx, t1)
        elif axis == 1:
            j, mj, inside = _advance(j, mj, dj, sj, ny, t1)
        else:
            k, mk, inside = _advance(k, mk, dk, sk, nz, t1)
        if not inside:
            break
    # The end cell is set even when rounding let the walk slip past it along an edge or corner.
    _mark(states, li, lj, lk, OCCUPIED if occupy_end else FREE)


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
    shared = origins.shape[0] == 1
    for r in range(ends.shape[0]):
        src = origins[0] if shared else origins[r]
        ox = (src[0] - grid_origin[0]) / resolution
        oy = (src[1] - grid_origin[1]) / resolution
        oz = (src[2] - grid_origin[2]) / resolution
        _walk(
            states,
            ox,
            oy,
            oz,
            (ends[r, 0] - grid_origin[0]) / resolution - ox,
            (ends[r, 1] - grid_origin[1]) / resolution - oy,
            (ends[r, 2] - grid_origin[2]) / resolution - oz,
            hit[r],
        )
