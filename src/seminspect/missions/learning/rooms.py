"""Training rooms of 004 Sec III-E: primitive obstacles around one semantic object.

A room is a closed box (floor, four walls, ceiling) holding K obstacles (boxes, cylinders and
spheres of random size, position and orientation) and one semantic object of N_f = 60 faces
(:mod:`.targets`: a cylinder, box, sphere or T-pipe). Rooms are 10 x 10 x 4 m (Table I) or, with
``EnvConfig.room_size_range``, drawn per room (Sec III-E: [4, 20] x [4, 20] x [2, 8] m).

Every solid is kept both as triangles (for the ray caster) and as an analytic shape, so the
robot's clearance to everything in the room is exact and cheap (:func:`clearance`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import matrix_from_euler_xyz
from seminspect.missions.learning.env_config import EnvConfig, TargetShape
from seminspect.missions.learning.solids import (
    BOX,
    CYLINDER,
    SPHERE,
    Solids,
    clearance,
    solid_distance,
    surface_gap,
)
from seminspect.missions.learning.targets import TARGET_FACES, Target, make_target
from seminspect.worlds.shapes import Piece, box, cylinder, sphere

__all__ = [
    "BOX",
    "CYLINDER",
    "SPHERE",
    "SURFACES",
    "TABLE1_OBSTACLES",
    "TARGET_FACES",
    "Room",
    "Solids",
    "clearance",
    "sample_room",
    "side_by_side",
    "stack_solids",
    "struck_surface",
]

#: Obstacle counts of 004 Table I.
TABLE1_OBSTACLES = (0, 4, 9, 14, 19)
#: What a crash can strike: the names :func:`struck_surface` gives.
SURFACES = ("wall", "floor", "ceiling", "object", "obstacle")


@dataclass(frozen=True)
class Room:
    """One sampled room: its solids, triangles and the robot's start.

    ``face_of_triangle`` gives the target face (0..59) of each triangle, or -1 for triangles of
    the room and its obstacles. The target is the first ``target_solids`` rows of ``solids``
    (two for a T-pipe); ``target_box`` bounds it (low, high corner); ``target_radius`` is its
    horizontal reach from the vertical axis through the box's centre.
    """

    size: NDArray[np.float64]
    solids: Solids
    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    face_of_triangle: NDArray[np.int64]
    start: NDArray[np.float64]
    start_yaw: float
    shape: TargetShape
    target_solids: int
    target_box: NDArray[np.float64]
    target_radius: float

    @property
    def obstacle_count(self) -> int:
        return len(self.solids.kind) - self.target_solids


def struck_surface(room: Room, point: NDArray[np.float64]) -> str:
    """Which of :data:`SURFACES` of ``room`` lies nearest to ``point``: what a robot that
    crashed there struck (a crash is a clearance below the robot's radius)."""
    p = np.asarray(point, dtype=np.float64)
    solids, k = room.solids, room.target_solids
    gaps = {
        "wall": min(p[0], p[1], room.size[0] - p[0], room.size[1] - p[1]),
        "floor": p[2],
        "ceiling": room.size[2] - p[2],
        "object": solid_distance(p[None], solids.rows(slice(None, k)))[0],
        "obstacle": solid_distance(p[None], solids.rows(slice(k, None)))[0],
    }
    return min(gaps, key=lambda name: gaps[name])


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
    config: EnvConfig | None = None,
    robot_clearance: float = 0.6,
    orbit_gap: float = 2.2,
) -> Room:
    """A room with ``obstacles`` primitives, the target and a free start, as ``config`` says.

    Its size is ``config.room_size`` or drawn from ``config.room_size_range``; its target's
    shape is drawn from ``config.target_shapes`` (no draw for a single shape). Obstacles may
    occlude the target (as in the paper); ``config.obstacle_rule`` keeps them clear of it
    (:func:`_add_obstacle`). The start is at least ``robot_clearance`` from everything. The
    target stands ``orbit_gap`` from the walls where the room allows, so a robot can circle it
    at the reference distance.
    """
    cfg = config or EnvConfig()
    extent = _room_extent(rng, obstacles, cfg)
    shapes = cfg.target_shapes
    shape = shapes[int(rng.integers(len(shapes)))] if len(shapes) > 1 else shapes[0]
    target = make_target(rng, shape, extent, orbit_gap)
    parts = _RoomParts()
    own = target.solids
    for i, kind in enumerate(own.kind):
        parts.add_solid(int(kind), own.centre[i], own.rotation[i], own.size[i])
    parts.add_mesh(target.vertices, target.triangles, target.faces)
    # "surface": the robot's width between the surfaces; "target-sphere" (policy v1): the
    # obstacle's bounding sphere kept robot_clearance beyond the target's
    gap = 2.0 * cfg.robot_radius if cfg.obstacle_rule == "surface" else None
    for _ in range(obstacles):
        _add_obstacle(parts, rng, extent, target, gap=gap, reach=target.reach + robot_clearance)
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
        shape=shape,
        target_solids=len(target.solids.kind),
        target_box=target.box,
        target_radius=target.radius,
    )


def _room_extent(rng: np.random.Generator, obstacles: int, config: EnvConfig) -> NDArray:
    """The room's size: fixed, or drawn uniformly per axis (004 Sec III-E)."""
    if obstacles < 0:
        raise InvalidInputError(f"obstacle count must be >= 0, got {obstacles}")
    if config.room_size_range is None:
        extent = np.asarray(config.room_size, dtype=np.float64)
    else:
        low, high = np.array(config.room_size_range, dtype=np.float64).T
        extent = rng.uniform(low, high)
    if np.any(extent < (4.0, 4.0, 2.0)):
        size = " x ".join(f"{x:g}" for x in extent.round(2))
        raise InvalidInputError(f"room must be at least 4 x 4 x 2 m, got {size} m")
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


def _add_obstacle(
    parts: _RoomParts,
    rng: np.random.Generator,
    extent: NDArray,
    target: Target,
    *,
    gap: float | None,
    reach: float,
) -> None:
    """A random primitive, placed anywhere and randomly turned, within 32 tries.

    With a ``gap`` (rule "surface") a try is kept when the obstacle's surface stays ``gap``
    from the target's (:func:`~.solids.surface_gap`); an obstacle no try places is left out.
    Without one (rule "target-sphere", policy v1's draws in its order) a try is kept when the
    obstacle's bounding sphere stays ``reach`` from the target's centre, else the last
    try stands.
    """
    kind, size, vertices, triangles = _obstacle(rng)
    if gap is None:
        needed = _bounding_radius(kind, size) + reach
        for _attempt in range(32):
            centre = rng.uniform(0.0, extent)
            if np.linalg.norm(centre - target.middle) > needed:
                break
        rotation = matrix_from_euler_xyz(rng.uniform(-math.pi, math.pi, size=3))
    else:
        apart = _bounding_radius(kind, size) + target.reach + gap  # bounding spheres: clear
        for _attempt in range(32):
            centre = rng.uniform(0.0, extent)
            rotation = matrix_from_euler_xyz(rng.uniform(-math.pi, math.pi, size=3))
            solid = Solids(np.array([kind], np.int8), centre[None], rotation[None], size[None])
            far = np.linalg.norm(centre - target.middle) > apart
            if far or surface_gap(solid, target.solids) >= gap:
                break
        else:
            return
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


def checked_rooms(rooms: Sequence[Room], count: int, largest: Sequence[float]) -> list[Room]:
    """``rooms`` as a list, checked as an env's ``reset(options={"rooms": ...})`` takes them:
    ``count`` rooms, each within the ``largest`` size its scene and maps hold."""
    given = list(rooms)
    if len(given) != count or not all(isinstance(room, Room) for room in given):
        raise InvalidInputError(f"options['rooms'] needs {count} Room objects, got {len(given)}")
    for room in given:
        if np.any(room.size > np.asarray(largest) + 1e-9):
            raise InvalidInputError(f"room {tuple(room.size)} exceeds the largest {largest}")
    return given
