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
from dataclasses import dataclass
from functools import cache

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
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


def _rotation(angles: NDArray[np.float64]) -> NDArray[np.float64]:
    (ca, cb, cc), (sa, sb, sc) = np.cos(angles), np.sin(angles)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return rz @ ry @ rx


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
    if obstacles < 0:
        raise InvalidInputError(f"obstacle count must be >= 0, got {obstacles}")
    extent = np.asarray(size, dtype=np.float64)
    if extent.shape != (3,) or np.any(extent < (4.0, 4.0, 2.0)):
        raise InvalidInputError(f"room must be at least 4 x 4 x 2 m, got {size}")
    radius, height = rng.uniform(0.3, 0.8), rng.uniform(1.0, min(2.5, extent[2] - 1.0))
    margin = np.minimum(radius + orbit_gap, extent[:2] / 2)
    target_xy = rng.uniform(margin, extent[:2] - margin)
    kinds, centres, rotations, sizes = [CYLINDER], [(*target_xy, height / 2)], [np.eye(3)], []
    sizes.append(np.array([radius, height / 2, 0.0]))
    verts: list[NDArray] = []
    tris: list[NDArray] = []
    tri_face: list[NDArray] = []
    mesh = (verts, tris, tri_face)
    t_verts, t_tris, t_faces = target_mesh(radius, height)
    _append(mesh, t_verts + centres[0], t_tris, t_faces)
    target_reach = math.hypot(radius, height / 2) + robot_clearance
    for _ in range(obstacles):
        kind, dims, o_verts, o_tris = _obstacle(rng)
        reach = _bounding_radius(kind, dims)
        for _attempt in range(32):
            centre = rng.uniform(0.0, extent)
            if np.linalg.norm(centre - centres[0]) > reach + target_reach:
                break
        rotation = _rotation(rng.uniform(-math.pi, math.pi, size=3))
        kinds.append(kind)
        centres.append(tuple(centre))
        rotations.append(rotation)
        sizes.append(dims)
        _append(mesh, o_verts @ rotation.T + centre, o_tris, np.full(len(o_tris), -1))
    s_verts, s_tris = _shell(extent)
    _append(mesh, s_verts, s_tris, np.full(len(s_tris), -1))
    solids = Solids(
        kind=np.array(kinds, dtype=np.int8),
        centre=np.array(centres, dtype=np.float64),
        rotation=np.array(rotations, dtype=np.float64),
        size=np.array(sizes, dtype=np.float64),
    )
    start = _free_start(rng, solids, extent, robot_clearance)
    return Room(
        size=extent,
        solids=solids,
        vertices=np.vstack(verts),
        triangles=np.vstack(tris),
        face_of_triangle=np.concatenate(tri_face),
        start=start,
        start_yaw=float(rng.uniform(-math.pi, math.pi)),
    )


def _append(
    mesh: tuple[list, list, list], vertices: NDArray, tris: NDArray, faces: NDArray
) -> None:
    """Add a part to the room's (vertices, triangles, face ids) lists, re-indexing triangles."""
    all_vertices, all_tris, all_faces = mesh
    base = sum(len(x) for x in all_vertices)
    all_vertices.append(np.asarray(vertices, dtype=np.float64))
    all_tris.append(np.asarray(tris, dtype=np.int64) + base)
    all_faces.append(np.asarray(faces, dtype=np.int64))


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
