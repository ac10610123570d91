"""Training rooms of 004 Sec III-E: primitive obstacles around one semantic object.

A room is a closed box (floor, four walls, ceiling) holding K obstacles (boxes, cylinders and
spheres of random size, position and orientation) and one semantic object: an upright cylinder
whose surface is split into N_f = 60 faces (12 sectors x 4 bands on the side, 12 sectors of
the top; the bottom rests on the floor and cannot be seen, so it is not scored). The paper's
object is a cuboid or other primitive with 60 faces; a cylinder keeps every face inspectable
from some free viewpoint, so 100 % coverage is feasible in an empty room.

Every solid is kept both as triangles (for the ray caster) and as an analytic shape, so the
robot's clearance to everything in the room is exact and cheap (:func:`clearance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import matrix_from_euler_xyz
from seminspect.worlds.shapes import Piece, box, cylinder, sphere

#: Shape codes of :class:`Solids`.
BOX, CYLINDER, SPHERE = 0, 1, 2
#: Faces of the semantic object (004 Sec III-E: N_f = 60).
TARGET_SECTORS, TARGET_BANDS = 12, 4
TARGET_FACES = TARGET_SECTORS * (TARGET_BANDS + 1)
#: Obstacle counts of 004 Table I.
TABLE1_OBSTACLES = (0, 4, 9, 14, 19)


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

    def rows(self, index: NDArray[np.int64]) -> Solids:
        """The solids of the rooms ``index`` of a batch (arrays with a leading room axis)."""
        return Solids(self.kind[index], self.centre[index], self.rotation[index], self.size[index])


@dataclass(frozen=True)
class Room:
    """One sampled room: its solids, triangles and the robot's start.

    ``face_of_triangle`` gives the target face (0..59) of each triangle, or -1 for triangles of
    the room and its obstacles. The target is ``solids`` row 0.
    """

    size: NDArray[np.float64]
    solids: Solids
    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    face_of_triangle: NDArray[np.int64]
    start: NDArray[np.float64]
    start_yaw: float

    @property
    def obstacle_count(self) -> int:
        return len(self.solids.kind) - 1


def clearance(
    points: NDArray[np.float64], solids: Solids, room_size: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance from each point to the nearest surface of its room (walls or solids).

    Exact signed distances of boxes, cylinders and spheres (negative inside a solid).
    ``points`` is ``(N, 3)``; the solids' arrays carry a leading ``N`` (one room per point, as in
    a batch of environments) or none (one room shared by every point).
    """
    pts = np.atleast_2d(points)
    walls = np.minimum(pts, room_size - pts).min(axis=1)
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
    return np.minimum(walls, solid_d.min(axis=-1, initial=np.inf))


def stack_solids(rooms: list[Room]) -> Solids:
    """The solids of several rooms padded to one count (padding: a far-away point sphere)."""
    count = max(len(r.solids.kind) for r in rooms)
    kind = np.full((len(rooms), count), SPHERE, dtype=np.int8)
    centre = np.full((len(rooms), count, 3), 1e6)
    rotation = np.broadcast_to(np.eye(3), (len(rooms), count, 3, 3)).copy()
    size = np.zeros((len(rooms), count, 3))
    for i, room in enumerate(rooms):
        n = len(room.solids.kind)
        kind[i, :n], centre[i, :n] = room.solids.kind, room.solids.centre
        rotation[i, :n], size[i, :n] = room.solids.rotation, room.solids.size
    return Solids(kind, centre, rotation, size)


def side_by_side(
    rooms: list[Room], spacing: float
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """The triangles of every room in one scene, room ``i`` shifted by ``i * spacing`` along x.

    Returns the vertices, the triangles and the target face of each triangle (-1: not the
    target), as in :class:`Room`.
    """
    vertices, triangles, faces, base = [], [], [], 0
    for i, room in enumerate(rooms):
        vertices.append(room.vertices + np.array([i * spacing, 0.0, 0.0]))
        triangles.append(room.triangles + base)
        faces.append(room.face_of_triangle)
        base += len(room.vertices)
    return np.vstack(vertices), np.vstack(triangles), np.concatenate(faces)


def _shell(size: NDArray) -> tuple[NDArray, NDArray]:
    piece = box((0.0, 0.0, 0.0), size)
    # Inward-facing walls: the camera sits inside the box.
    return piece.vertices, piece.faces[:, ::-1]


def target_mesh(radius: float, height: float) -> tuple[NDArray, NDArray, NDArray]:
    """Side (sectors x bands quads) and top cap (sector triangles) of the semantic cylinder.

    Returns vertices, triangles and the face (0..59) of each triangle, centred on the origin.
    """
    angles = np.linspace(0.0, 2.0 * math.pi, TARGET_SECTORS, endpoint=False)
    heights = np.linspace(-height / 2, height / 2, TARGET_BANDS + 1)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    side = np.array([(x, y, z) for z in heights for x, y in ring])
    top_centre = np.array([[0.0, 0.0, height / 2]])
    vertices = np.vstack([side, top_centre])
    tris, faces = [], []
    for band in range(TARGET_BANDS):
        for s in range(TARGET_SECTORS):
            a, b = band * TARGET_SECTORS + s, band * TARGET_SECTORS + (s + 1) % TARGET_SECTORS
            c, d = a + TARGET_SECTORS, b + TARGET_SECTORS
            face = band * TARGET_SECTORS + s
            tris += [(a, b, d), (a, d, c)]
            faces += [face, face]
    top_ring, centre = TARGET_BANDS * TARGET_SECTORS, len(side)
    for s in range(TARGET_SECTORS):
        tris.append((top_ring + s, top_ring + (s + 1) % TARGET_SECTORS, centre))
        faces.append(TARGET_BANDS * TARGET_SECTORS + s)
    return vertices, np.array(tris, dtype=np.int64), np.array(faces, dtype=np.int64)


@cache
def _unit_mesh(kind: int) -> Piece:
    """Unit cylinder (radius 1, half height 1) or unit sphere, meshed once and scaled per use."""
    return cylinder(1.0, 2.0, "", sections=12) if kind == CYLINDER else sphere(1.0, "")


def _obstacle(rng: np.random.Generator) -> tuple[int, NDArray, NDArray, NDArray]:
    """Shape code, analytic size, vertices and triangles of a random primitive (0.4-1.5 m)."""
    kind = int(rng.integers(3))
    half = rng.uniform(0.2, 0.75, size=3)
    if kind == BOX:
        piece = box(-half, half)
        return kind, half, piece.vertices, piece.faces
    unit = _unit_mesh(kind)
    if kind == CYLINDER:
        size = np.array([half[0], half[1], 0.0])
        return kind, size, unit.vertices * (half[0], half[0], half[1]), unit.faces
    return kind, np.array([half[0], 0.0, 0.0]), unit.vertices * half[0], unit.faces


def _bounding_radius(kind: int, size: NDArray) -> float:
    return float(np.linalg.norm(size) if kind == BOX else np.hypot(size[0], size[1]))


def sample_room(
    rng: np.random.Generator,
    obstacles: int,
    size: tuple[float, float, float] = (10.0, 10.0, 4.0),
    robot_clearance: float = 0.6,
    orbit_gap: float = 2.2,
) -> Room:
    """A room of ``size`` metres with ``obstacles`` primitives, the target and a free start.

    Obstacles may occlude the target (as in the paper) but leave a gap of at least
    ``robot_clearance`` around it, so its faces are not walled in; the start is at least that
    far from everything. The target stands ``orbit_gap`` from the walls where the room allows,
    so a robot can circle it at the reference distance.
    """
    extent = _checked_extent(obstacles, size)
    parts = _RoomParts()
    target_reach = _add_target(parts, rng, extent, orbit_gap) + robot_clearance
    for _ in range(obstacles):
        _add_obstacle(parts, rng, extent, target_reach)
    parts.add_mesh(*_shell(extent))
    solids = parts.solids()
    start = _free_start(rng, solids, extent, robot_clearance)
    return Room(
        size=extent,
        solids=solids,
        vertices=np.vstack(parts.vertices),
        triangles=np.vstack(parts.triangles),
        face_of_triangle=np.concatenate(parts.faces),
        start=start,
        start_yaw=float(rng.uniform(-math.pi, math.pi)),
    )


def _checked_extent(obstacles: int, size: tuple[float, float, float]) -> NDArray[np.float64]:
    if obstacles < 0:
        raise InvalidInputError(f"obstacle count must be >= 0, got {obstacles}")
    extent = np.asarray(size, dtype=np.float64)
    if extent.shape != (3,) or np.any(extent < (4.0, 4.0, 2.0)):
        raise InvalidInputError(f"room must be at least 4 x 4 x 2 m, got {size}")
    return extent


@dataclass
class _RoomParts:
    """A room's solids and triangles as they are added: the target first, the shell last."""

    kinds: list[int] = field(default_factory=list)
    centres: list[NDArray[np.float64]] = field(default_factory=list)
    rotations: list[NDArray[np.float64]] = field(default_factory=list)
    sizes: list[NDArray[np.float64]] = field(default_factory=list)
    vertices: list[NDArray[np.float64]] = field(default_factory=list)
    triangles: list[NDArray[np.int64]] = field(default_factory=list)
    faces: list[NDArray[np.int64]] = field(default_factory=list)

    def add_solid(self, kind: int, centre: NDArray, rotation: NDArray, size: NDArray) -> None:
        self.kinds.append(kind)
        self.centres.append(centre)
        self.rotations.append(rotation)
        self.sizes.append(size)

    def add_mesh(self, vertices: NDArray, triangles: NDArray, faces: NDArray | None = None) -> None:
        """Triangles re-indexed after those already added; ``faces`` None: not the target."""
        base = sum(len(x) for x in self.vertices)
        self.vertices.append(np.asarray(vertices, dtype=np.float64))
        self.triangles.append(np.asarray(triangles, dtype=np.int64) + base)
        self.faces.append(
            np.full(len(triangles), -1) if faces is None else np.asarray(faces, dtype=np.int64)
        )

    def solids(self) -> Solids:
        return Solids(
            kind=np.array(self.kinds, dtype=np.int8),
            centre=np.array(self.centres, dtype=np.float64),
            rotation=np.array(self.rotations, dtype=np.float64),
            size=np.array(self.sizes, dtype=np.float64),
        )


def _add_target(
    parts: _RoomParts, rng: np.random.Generator, extent: NDArray, orbit_gap: float
) -> float:
    """Place the semantic cylinder ``orbit_gap`` from the walls; returns its bounding radius."""
    radius, height = rng.uniform(0.3, 0.8), rng.uniform(1.0, min(2.5, extent[2] - 1.0))
    margin = np.minimum(radius + orbit_gap, extent[:2] / 2)
    centre = np.array([*rng.uniform(margin, extent[:2] - margin), height / 2])
    parts.add_solid(CYLINDER, centre, np.eye(3), np.array([radius, height / 2, 0.0]))
    vertices, triangles, faces = target_mesh(radius, height)
    parts.add_mesh(vertices + centre, triangles, faces)
    return math.hypot(radius, height / 2)


def _add_obstacle(
    parts: _RoomParts, rng: np.random.Generator, extent: NDArray, target_reach: float
) -> None:
    """A random primitive, placed (within 32 tries) so that it stays ``target_reach`` clear of
    the target's centre; randomly turned."""
    kind, size, vertices, triangles = _obstacle(rng)
    needed = _bounding_radius(kind, size) + target_reach
    for _attempt in range(32):
        centre = rng.uniform(0.0, extent)
        if np.linalg.norm(centre - parts.centres[0]) > needed:
            break
    rotation = matrix_from_euler_xyz(rng.uniform(-math.pi, math.pi, size=3))
    parts.add_solid(kind, centre, rotation, size)
    parts.add_mesh(vertices @ rotation.T + centre, triangles)


def _free_start(
    rng: np.random.Generator, solids: Solids, size: NDArray, margin: float
) -> NDArray[np.float64]:
    """The candidate start with the most clearance among those meeting ``margin``.

    Candidates are drawn in batches; the first batch holding a clear one decides. Rooms so
    cluttered that nothing is clear within 8 batches take the clearest candidate seen.
    """
    best, best_gap = size / 2, -np.inf
    for _ in range(8):
        candidates = rng.uniform(margin, size - margin, size=(64, 3))
        gaps = clearance(candidates, solids, size)
        clear = np.flatnonzero(gaps >= margin)
        if len(clear):
            return candidates[clear[0]]
        if gaps.max() > best_gap:
            best, best_gap = candidates[int(np.argmax(gaps))], float(gaps.max())
    return best
