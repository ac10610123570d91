"""Compiled ray traversal through a voxel grid (Amanatides and Woo, "A fast voxel traversal
algorithm for ray tracing", 1987).

Each ray is clipped to the grid, then walked cell by cell: every cell it crosses becomes free,
the cell holding its end point becomes occupied if the ray hit a surface there. Occupied cells
stay occupied (a grazing ray never erases a surface another ray saw), which keeps the map
conservative for planning.

The walks therefore commute: a cell ends occupied if it was or any ray ends on a surface in it,
else free if it was or any ray crosses or ends in it. So rays may be walked on several threads
at once, each only ever turning unknown cells free, with the occupied end cells set after all
of them: the same map as one thread walking the rays in order.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from seminspect.core.threads import run_dealt, worth_splitting

UNKNOWN = np.uint8(0)
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
    cell: int, boundary: float, per_cell: float, step: int, edge: int, t1: float
) -> tuple[int, float, bool]:
    """Step one cell along an axis; False once the ray ends first or the step reaches
    ``edge``, the index just past the grid."""
    if boundary > t1:
        return cell, boundary, False
    cell += step
    return cell, boundary + per_cell, cell != edge


@numba.njit(cache=True)
def _walk(  # noqa: PLR0917 - scalars keep the per-ray walk free of allocations
    cells: np.ndarray,
    shape: tuple[int, int, int],
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    hit: bool,
    t_start: float,
) -> int:
    """Free every cell of ``o + t d`` for ``t`` from ``t_start`` (clipped to the grid) to 1;
    return the flat index of the end cell when the ray ends on a surface there (the caller
    occupies it), else -1.

    ``cells`` is the map's C-ordered states, flattened: the walk moves one index by the
    axis strides instead of indexing in 3D, and writes a cell only when it is still unknown
    (most cells near the sensor were freed by earlier rays). Three scalars per axis rather
    than small arrays: the walk runs once per ray, and allocating its state dominated short
    rays.
    """
    nx, ny, nz = shape
    t0, t1 = _clip_axis(t_start, 1.0, ox, dx, nx)
    t0, t1 = _clip_axis(t0, t1, oy, dy, ny)
    t0, t1 = _clip_axis(t0, t1, oz, dz, nz)
    if t0 > t1:
        return -1
    i, j, k = _cell(ox + t0 * dx, nx), _cell(oy + t0 * dy, ny), _cell(oz + t0 * dz, nz)
    li, lj, lk = _cell(ox + t1 * dx, nx), _cell(oy + t1 * dy, ny), _cell(oz + t1 * dz, nz)
    si, mi, di = _start_axis(ox, dx, i)
    sj, mj, dj = _start_axis(oy, dy, j)
    sk, mk, dk = _start_axis(oz, dz, k)
    occupy_end = hit and 0.0 <= ox + dx < nx and 0.0 <= oy + dy < ny and 0.0 <= oz + dz < nz
    # The index one step past the grid on each axis, in the direction the walk moves.
    ei, ej, ek = (nx if si > 0 else -1), (ny if sj > 0 else -1), (nz if sk > 0 else -1)
    index, last = (i * ny + j) * nz + k, (li * ny + lj) * nz + lk
    for _ in range(nx + ny + nz + 3):
        if index == last:
            break
        if cells[index] == UNKNOWN:
            cells[index] = FREE
        # The axis whose next boundary comes first; ties go to the lower axis. The walk
        # stops once the ray ends inside the current cell or steps off the grid.
        axis = (2 if mk < mj else 1) if mj < mi else (2 if mk < mi else 0)
        if axis == 0:
            i, mi, inside = _advance(i, mi, di, si, ei, t1)
            index += si * ny * nz
        elif axis == 1:
            j, mj, inside = _advance(j, mj, dj, sj, ej, t1)
            index += sj * nz
        else:
            k, mk, inside = _advance(k, mk, dk, sk, ek, t1)
            index += sk
        if not inside:
            break
    # The end cell is set even when rounding let the walk slip past it along an edge or corner.
    if occupy_end:
        return last
    if cells[last] == UNKNOWN:
        cells[last] = FREE
    return -1


#: Below this many rays per thread, a second thread costs more than it saves.
MIN_RAYS_PER_THREAD = 4096


def integrate_rays_kernel(  # noqa: PLR0917 - the compiled kernel's arrays, passed through
    states: np.ndarray,
    grid_origin: np.ndarray,
    resolution: float,
    origins: np.ndarray,
    ends: np.ndarray,
    hit: np.ndarray,
    carve_from: np.ndarray,
    threads: int = 1,
) -> None:
    """Walk every ray ``origins[r or 0] -> ends[r]`` (world metres) through ``states``.

    ``carve_from[r]`` in ``[0, 1]`` is the fraction of ray ``r`` before which it frees nothing
    (see ``mapping.carving``); an empty array frees every ray from its origin. With ``threads``
    > 1 blocks of rays are dealt out to that many threads and the hits occupied after every
    walk (the module's docstring says why the map is the same).
    """
    arrays = (states, grid_origin, resolution, origins, ends, hit, carve_from)
    count = ends.shape[0]
    if not worth_splitting(count, threads, MIN_RAYS_PER_THREAD):  # one thread: hits at once
        _walk_rays(*arrays, 0, count, np.empty(0, dtype=np.int64))
        return
    occupy = np.empty(count, dtype=np.int64)

    def walk(block: slice) -> None:
        _walk_rays(*arrays, block.start, block.stop, occupy)

    run_dealt(walk, count, threads, MIN_RAYS_PER_THREAD)
    _occupy(states, occupy)


@numba.njit(cache=True, nogil=True)
def _walk_rays(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    states: np.ndarray,
    grid_origin: np.ndarray,
    resolution: float,
    origins: np.ndarray,
    ends: np.ndarray,
    hit: np.ndarray,
    carve_from: np.ndarray,
    first: int,
    stop: int,
    occupy: np.ndarray,
) -> None:
    """Walk rays ``first`` to ``stop - 1``; occupy their hits at once, or, given an ``occupy``
    array for every ray, write each ray's cell to occupy there (-1: none) for later."""
    thinned = carve_from.shape[0] > 0
    deferred = occupy.shape[0] > 0
    cells = states.reshape(-1)
    shape = states.shape
    shared = origins.shape[0] == 1
    for r in range(first, stop):
        src = origins[0] if shared else origins[r]
        ox = (src[0] - grid_origin[0]) / resolution
        oy = (src[1] - grid_origin[1]) / resolution
        oz = (src[2] - grid_origin[2]) / resolution
        end = _walk(
            cells,
            shape,
            ox,
            oy,
            oz,
            (ends[r, 0] - grid_origin[0]) / resolution - ox,
            (ends[r, 1] - grid_origin[1]) / resolution - oy,
            (ends[r, 2] - grid_origin[2]) / resolution - oz,
            hit[r],
            carve_from[r] if thinned else 0.0,
        )
        if deferred:
            occupy[r] = end
        elif end >= 0:
            cells[end] = OCCUPIED


@numba.njit(cache=True, nogil=True)
def _occupy(states: np.ndarray, occupy: np.ndarray) -> None:
    """Occupy the end cells of the rays that hit (``occupy[r] >= 0``)."""
    cells = states.reshape(-1)
    for index in occupy:
        if index >= 0:
            cells[index] = OCCUPIED
