"""Closed, labelled primitive solids from which the generators assemble worlds.

A :class:`Piece` is a small triangle mesh with one part label per face. Every piece is a closed
solid with outward-facing triangles, so the volume of an object made of non-overlapping pieces is
exact, and each face knows which part it belongs to (the top of the front section of a car is its
hood, its sides are doors, ...).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError


@dataclass(frozen=True)
class Piece:
    """Vertices ``(V, 3)``, triangles ``(F, 3)`` and one part label per triangle."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    labels: tuple[str, ...]

    def transformed(self, matrix: ArrayLike) -> Piece:
        """The piece moved by a 4x4 homogeneous transform."""
        m = np.asarray(matrix, dtype=np.float64)
        moved = self.vertices @ m[:3, :3].T + m[:3, 3]
        faces = self.faces if np.linalg.det(m[:3, :3]) > 0 else self.faces[:, ::-1]
        return Piece(moved, faces, self.labels)

    def relabelled(self, label: str) -> Piece:
        """The same solid with every face carrying ``label``."""
        return Piece(self.vertices, self.faces, (label,) * len(self.faces))


def _outward(vertices: NDArray, faces: NDArray) -> NDArray:
    """Flip triangles of a convex solid whose normal points towards its centre."""
    centre = vertices.mean(axis=0)
    tri = vertices[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    inward = np.einsum("ij,ij->i", normals, tri.mean(axis=1) - centre) < 0
    fixed = faces.copy()
    fixed[inward] = fixed[inward][:, ::-1]
    return fixed


def prism_xz(
    outline: Sequence[tuple[float, float]],
    y_range: tuple[float, float],
    edge_labels: Sequence[str],
    left: str,
    right: str,
) -> Piece:
    """A convex polygon in the x-z plane extruded along y.

    Args:
        outline: convex polygon ``(x, z)``, counter-clockwise or clockwise.
        y_range: the extrusion from ``y_min`` to ``y_max``.
        edge_labels: label of the side wall along each outline edge (edge ``i`` runs from
            corner ``i`` to corner ``i + 1``).
        left: label of the cap at ``y_max`` (a vehicle's left side, its +y).
        right: label of the cap at ``y_min``.
    """
    ring = np.asarray(outline, dtype=np.float64)
    n = len(ring)
    if n < 3 or len(edge_labels) != n:
        raise InvalidInputError("a prism needs >= 3 corners and one label per edge")
    y0, y1 = y_range
    low = np.column_stack([ring[:, 0], np.full(n, y0), ring[:, 1]])
    high = np.column_stack([ring[:, 0], np.full(n, y1), ring[:, 1]])
    vertices = np.vstack([low, high])
    faces: list[tuple[int, int, int]] = []
    labels: list[str] = []
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, j, n + j), (i, n + j, n + i)]
        labels += [edge_labels[i]] * 2
    for k in range(1, n - 1):
        faces += [(0, k, k + 1), (n, n + k, n + k + 1)]
        labels += [right, left]
    face_array = np.asarray(faces, dtype=np.int64)
    return Piece(vertices, _outward(vertices, face_array), tuple(labels))


def box(lower: ArrayLike, upper: ArrayLike, label: str = "", **sides: str) -> Piece:
    """An axis-aligned box; ``sides`` relabels faces by direction.

    Keyword names are ``front`` (+x), ``back`` (-x), ``left`` (+y), ``right`` (-y), ``top``
    (+z) and ``bottom`` (-z); faces not named carry ``label``.
    """
    unknown = set(sides) - {"front", "back", "left", "right", "top", "bottom"}
    if unknown:
        raise InvalidInputError(f"unknown box sides {sorted(unknown)}")
    (x0, y0, z0), (x1, y1, z1) = np.asarray(lower, float), np.asarray(upper, float)
    if not (x1 > x0 and y1 > y0 and z1 > z0):
        raise InvalidInputError(f"empty box {lower!s} - {upper!s}")
    edge = [sides.get(k, label) for k in ("bottom", "front", "top", "back")]
    return prism_xz(
        [(x0, z0), (x1, z0), (x1, z1), (x0, z1)],
        (y0, y1),
        edge,
        left=sides.get("left", label),
        right=sides.get("right", label),
    )


def cylinder(radius: float, length: float, label: str, sections: int = 16) -> Piece:
    """A closed cylinder along z, centred on the origin."""
    mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=sections)
    return Piece(np.asarray(mesh.vertices), np.asarray(mesh.faces), (label,) * len(mesh.faces))


def sphere(radius: float, label: str, subdivisions: int = 1) -> Piece:
    """A closed icosphere centred on the origin."""
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return Piece(np.asarray(mesh.vertices), np.asarray(mesh.faces), (label,) * len(mesh.faces))


def pose_matrix(
    translation: ArrayLike = (0.0, 0.0, 0.0),
    yaw: float = 0.0,
    euler_xyz: ArrayLike | None = None,
    scale: ArrayLike = 1.0,
) -> NDArray[np.float64]:
    """4x4 transform: scale, then rotate (``euler_xyz`` radians, else ``yaw``), then move."""
    matrix = np.eye(4)
    if euler_xyz is None:
        c, s = math.cos(yaw), math.sin(yaw)
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    else:
        rotation = Rotation.from_euler("xyz", euler_xyz).as_matrix()
    matrix[:3, :3] = rotation * np.broadcast_to(np.asarray(scale, float), (3,))
    matrix[:3, 3] = np.asarray(translation, dtype=np.float64)
    return matrix


def rotated_y_axis(piece: Piece) -> Piece:
    """Turn a z-axis primitive (cylinder) so that its axis runs along y (a wheel's axle)."""
    return piece.transformed(pose_matrix(euler_xyz=(math.pi / 2, 0.0, 0.0)))
