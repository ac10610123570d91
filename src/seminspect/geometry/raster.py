"""Rasterising triangles into grid cells.

:func:`cells_touching_triangles` marks every cell of a regular grid whose closed box touches a
triangle, using the separating-axis triangle/box test (Akenine-Möller, "Fast 3D triangle-box
overlap testing", 2001). Cells may be anisotropic, so a single tall layer gives a top-down
footprint of everything inside a height band. Worlds use it for collision fields, maps for the
occupancy map built straight from a mesh.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError

#: Boxes are grown by this fraction of their size so that a triangle lying exactly on a cell
#: face counts as touching both neighbours (float rounding would otherwise pick one at random).
_TOUCH_TOLERANCE = 1e-6


@numba.njit(cache=True)
def _separated_on_axis(ax: float, ay: float, az: float, v: np.ndarray, half: np.ndarray) -> bool:
    """Whether the projections of the triangle ``v`` and the centred box ``half`` are disjoint."""
    p0 = ax * v[0, 0] + ay * v[0, 1] + az * v[0, 2]
    p1 = ax * v[1, 0] + ay * v[1, 1] + az * v[1, 2]
    p2 = ax * v[2, 0] + ay * v[2, 1] + az * v[2, 2]
    radius = half[0] * abs(ax) + half[1] * abs(ay) + half[2] * abs(az)
    return min(p0, p1, p2) > radius or max(p0, p1, p2) < -radius


@numba.njit(cache=True)
def _triangle_touches_box(tri: np.ndarray, centre: np.ndarray, half: np.ndarray) -> bool:
    """Separating-axis test of a triangle against an axis-aligned box (centre, half sizes)."""
    v = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            v[i, k] = tri[i, k] - centre[k]
    # The box's own axes: compare the triangle's extent with the box.
    for k in range(3):
        lo = min(v[0, k], v[1, k], v[2, k])
        hi = max(v[0, k], v[1, k], v[2, k])
        if lo > half[k] or hi < -half[k]:
            return False
    # The nine cross products of box axes and triangle edges.
    for i in range(3):
        ex = v[(i + 1) % 3, 0] - v[i, 0]
        ey = v[(i + 1) % 3, 1] - v[i, 1]
        ez = v[(i + 1) % 3, 2] - v[i, 2]
        if _separated_on_axis(0.0, -ez, ey, v, half):
            return False
        if _separated_on_axis(ez, 0.0, -ex, v, half):
            return False
        if _separated_on_axis(-ey, ex, 0.0, v, half):
            return False
    # The triangle's plane.
    e0 = v[1] - v[0]
    e1 = v[2] - v[0]
    nx = e0[1] * e1[2] - e0[2] * e1[1]
    ny = e0[2] * e1[0] - e0[0] * e1[2]
    nz = e0[0] * e1[1] - e0[1] * e1[0]
    return not _separated_on_axis(nx, ny, nz, v, half)


@numba.njit(cache=True)
def _rasterise(
    triangles: np.ndarray, origin: np.ndarray, cell: np.ndarray, out: np.ndarray
) -> None:
    shape = out.shape
    half = cell * (0.5 + _TOUCH_TOLERANCE)
    centre = np.empty(3)
    lo = np.empty(3, dtype=np.int64)
    hi = np.empty(3, dtype=np.int64)
    for t in range(triangles.shape[0]):
        tri = triangles[t]
        inside = True
        for k in range(3):
            tmin = min(tri[0, k], tri[1, k], tri[2, k])
            tmax = max(tri[0, k], tri[1, k], tri[2, k])
            lo[k] = max(0, math.floor((tmin - origin[k]) / cell[k] - _TOUCH_TOLERANCE))
            hi[k] = min(shape[k] - 1, math.floor((tmax - origin[k]) / cell[k] + _TOUCH_TOLERANCE))
            if lo[k] > hi[k]:
                inside = False
        if not inside:
            continue
        for i in range(lo[0], hi[0] + 1):
            centre[0] = origin[0] + (i + 0.5) * cell[0]
            for j in range(lo[1], hi[1] + 1):
                centre[1] = origin[1] + (j + 0.5) * cell[1]
                for k in range(lo[2], hi[2] + 1):
                    if out[i, j, k]:
                        continue
                    centre[2] = origin[2] + (k + 0.5) * cell[2]
                    if _triangle_touches_box(tri, centre, half):
                        out[i, j, k] = True


def cells_touching_triangles(
    triangles: ArrayLike,
    origin: ArrayLike,
    cell_size: float | ArrayLike,
    shape: tuple[int, int, int],
) -> NDArray[np.bool_]:
    """Boolean grid of ``shape``: True where the closed cell box touches any triangle.

    Args:
        triangles: ``(F, 3, 3)`` triangle corners in world coordinates.
        origin: world coordinates of the grid's minimum corner.
        cell_size: edge length of a cell, one number or one per axis.
        shape: number of cells along x, y and z.
    """
    tris = np.ascontiguousarray(triangles, dtype=np.float64)
    if tris.ndim != 3 or tris.shape[1:] != (3, 3):
        raise InvalidInputError(f"triangles must have shape (F, 3, 3), got {tris.shape}")
    cell = np.broadcast_to(np.asarray(cell_size, dtype=np.float64), (3,)).copy()
    if not np.all(np.isfinite(cell) & (cell > 0)):
        raise InvalidInputError(f"cell size must be positive, got {cell.tolist()}")
    out = np.zeros(tuple(int(n) for n in shape), dtype=np.bool_)
    if tris.shape[0] and out.size:
        _rasterise(tris, np.asarray(origin, dtype=np.float64), cell, out)
    return out
