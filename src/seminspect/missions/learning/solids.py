"""Analytic solids of the 004 rooms: boxes, cylinders and spheres, their distances and bounds.

Every solid of a room (the semantic object's parts and the obstacles) is kept as an analytic
shape beside its triangles, so the robot's clearance to everything is exact and cheap
(:func:`clearance`), and so is the gap between two solids (:func:`surface_gap`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np
from numpy.typing import NDArray

#: Shape codes of :class:`Solids`.
BOX, CYLINDER, SPHERE = 0, 1, 2


@dataclass(frozen=True)
class Solids:
    """Analytic solids of one room: shape code, centre, rotation (local to room) and size.

    ``size`` holds half extents for a box, (radius, half height, 0) for a cylinder along its
    local z axis and (radius, 0, 0) for a sphere.
    """

    kind: NDArray[np.int8]
    centre: NDArray[np.float64]
    rotation: NDArray[np.float64]
    size: NDArray[np.float64]

    def rows(self, index: NDArray[np.int64] | slice) -> Solids:
        """The rows ``index`` of the leading axis: rooms of a batch, or solids of one room."""
        return Solids(self.kind[index], self.centre[index], self.rotation[index], self.size[index])


def solid_distance(points: NDArray[np.float64], solids: Solids) -> NDArray[np.float64]:
    """Signed distance from each point to the nearest solid (negative inside; inf: none).

    Exact for boxes, cylinders and spheres. ``points`` is ``(N, 3)``; the solids' arrays carry
    a leading ``N`` (one room per point, as in a batch of environments) or none (one room
    shared by every point).
    """
    pts = np.atleast_2d(points)
    local = np.einsum("...kji,...kj->...ki", solids.rotation, pts[:, None, :] - solids.centre)
    half = np.broadcast_to(solids.size, local.shape)
    box_q = np.abs(local) - half
    box_d = np.linalg.norm(np.maximum(box_q, 0.0), axis=-1) + np.minimum(box_q.max(axis=-1), 0.0)
    radial = np.hypot(local[..., 0], local[..., 1]) - half[..., 0]
    axial = np.abs(local[..., 2]) - half[..., 1]
    cyl_q = np.stack([radial, axial], axis=-1)
    cyl_d = np.linalg.norm(np.maximum(cyl_q, 0.0), axis=-1) + np.minimum(cyl_q.max(axis=-1), 0.0)
    sph_d = np.linalg.norm(local, axis=-1) - half[..., 0]
    kind = np.broadcast_to(solids.kind, sph_d.shape)
    solid_d = np.where(kind == BOX, box_d, np.where(kind == CYLINDER, cyl_d, sph_d))
    return solid_d.min(axis=-1, initial=np.inf)


def clearance(
    points: NDArray[np.float64], solids: Solids, room_size: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance from each point to the nearest surface of its room (walls or solids).

    As :func:`solid_distance`, with the room's walls, floor and ceiling; ``room_size`` is
    ``(3,)`` or one row per point.
    """
    pts = np.atleast_2d(points)
    walls = np.minimum(pts, room_size - pts).min(axis=1)
    return np.minimum(walls, solid_distance(pts, solids))


def solid_bounds(
    kind: int, centre: NDArray[np.float64], rotation: NDArray[np.float64], size: NDArray
) -> NDArray[np.float64]:
    """Axis-aligned bound ``(2, 3)`` (low, high corner) of one solid."""
    if kind == BOX:
        half = np.abs(rotation) @ size
    elif kind == CYLINDER:
        axis = rotation[:, 2]  # the local z axis in room coordinates
        half = size[1] * np.abs(axis) + size[0] * np.sqrt(np.maximum(1.0 - axis**2, 0.0))
    else:
        half = np.full(3, size[0])
    return np.stack([centre - half, centre + half])


def surface_points(kind: int, centre: NDArray, rotation: NDArray, size: NDArray) -> NDArray:
    """Points on the surface of one solid, at most about a tenth of its size apart."""
    scale = size if kind == BOX else (size[0], size[0], size[1]) if kind == CYLINDER else size[0]
    return (_unit_surface(kind) * scale) @ np.asarray(rotation).T + centre


def surface_gap(near: Solids, far: Solids) -> float:
    """Gap between the surfaces of two groups of solids (negative: they overlap).

    Measured both ways, from points on each group's surface to the other's analytic solids,
    so a corner or an edge of either side is caught; the points are about a tenth of a solid's
    size apart, so the gap is over-estimated by at most a few centimetres for the room's
    0.4-1.5 m solids.
    """
    gaps = [
        solid_distance(np.vstack([surface_points(*row) for row in _rows(a)]), b).min()
        for a, b in ((near, far), (far, near))
    ]
    return float(min(gaps))


def _rows(solids: Solids) -> list[tuple[int, NDArray, NDArray, NDArray]]:
    return [
        (int(k), solids.centre[i], solids.rotation[i], solids.size[i])
        for i, k in enumerate(solids.kind)
    ]


@cache
def _unit_surface(kind: int) -> NDArray[np.float64]:
    """Points on the unit box (half extent 1), cylinder (radius 1, half height 1) or sphere."""
    grid = np.linspace(-1.0, 1.0, 13)
    if kind == BOX:
        u, v = (a.ravel() for a in np.meshgrid(grid, grid))
        one = np.ones_like(u)
        faces = [np.roll([s * one, u, v], axis, axis=0).T for axis in range(3) for s in (-1.0, 1.0)]
        return np.vstack(faces)
    if kind == CYLINDER:
        angle = np.linspace(0.0, 2.0 * math.pi, 48, endpoint=False)
        ring = np.column_stack([np.cos(angle), np.sin(angle)])
        side = [np.column_stack([ring, np.full(48, z)]) for z in grid]
        caps = [
            np.column_stack([rho * ring, np.full(48, z)])
            for rho in (0.25, 0.5, 0.75)
            for z in (-1.0, 1.0)
        ]
        return np.vstack([*side, *caps, [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]]])
    # Fibonacci sphere: near-even spacing
    count = 600
    z = 1.0 - (np.arange(count) + 0.5) * 2.0 / count
    turn = np.arange(count) * math.pi * (3.0 - math.sqrt(5.0))
    rho = np.sqrt(1.0 - z**2)
    return np.column_stack([rho * np.cos(turn), rho * np.sin(turn), z])
