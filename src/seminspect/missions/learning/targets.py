"""The semantic object of the 004 rooms: four shapes, each meshed into N_f = 60 faces.

004 trains on primitives as the object (Sec III-E: N_f = 60; Fig 3 shows a cuboid) and meets a
sphere and a T-shaped pipe in the field (Sec V). Each shape here is

- a mesh whose triangles carry a face id 0..59 (every id used), wound so that their normals
  point out of the object; what rests on the floor cannot be seen and is not meshed;
- its analytic solids (:class:`~seminspect.missions.learning.solids.Solids` rows: the
  T-pipe is two cylinders), for the robot's contact and the obstacles' gaps;
- its axis-aligned bound, against which the camera culls its rays.

Sizes are random, about a cylinder's of 0.6-1.6 m across and 1-2.5 m tall (lower in low rooms).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.geometry.transforms import matrix_from_euler_xyz
from seminspect.missions.learning.env_config import TargetShape
from seminspect.missions.learning.solids import BOX, CYLINDER, SPHERE, Solids, solid_bounds

#: Faces of the semantic object (004 Sec III-E: N_f = 60).
TARGET_FACES = 60
#: The cylinder's layout: 12 sectors x 4 bands on the side, then the 12 sectors of its top.
CYLINDER_SECTORS, CYLINDER_BANDS = 12, 4

Mesh = tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]


@dataclass(frozen=True)
class Target:
    """One semantic object placed in a room (room coordinates)."""

    shape: TargetShape
    solids: Solids
    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    faces: NDArray[np.int64]
    box: NDArray[np.float64]  # (2, 3): low and high corner
    middle: NDArray[np.float64]  # centre of the bounding sphere
    reach: float  # radius of the bounding sphere
    radius: float  # horizontal extent about the vertical axis through middle


def make_target(
    rng: np.random.Generator, shape: TargetShape, extent: NDArray, orbit_gap: float
) -> Target:
    """A random ``shape`` standing on the floor ``orbit_gap`` from the walls where the room
    allows, so that a robot can circle it at the reference distance."""
    height_cap = min(2.5, float(extent[2]) - 1.0)
    if shape == "cylinder":
        return _cylinder(rng, extent, orbit_gap, height_cap)
    if shape == "box":
        return _box(rng, extent, orbit_gap, height_cap)
    if shape == "sphere":
        return _sphere(rng, extent, orbit_gap, height_cap)
    return _t_pipe(rng, extent, orbit_gap, height_cap)


def _place(rng: np.random.Generator, extent: NDArray, radius: float, orbit_gap: float) -> NDArray:
    """A floor position (x, y) leaving ``orbit_gap`` between the walls and ``radius``."""
    margin = np.minimum(radius + orbit_gap, extent[:2] / 2)
    return rng.uniform(margin, extent[:2] - margin)


def _cylinder(rng: np.random.Generator, extent: NDArray, gap: float, cap: float) -> Target:
    """Upright cylinder; the draws and the mesh are those policy v1 was trained on."""
    radius, height = rng.uniform(0.3, 0.8), rng.uniform(1.0, cap)
    centre = np.array([*_place(rng, extent, radius, gap), height / 2])
    heights = np.linspace(-height / 2, height / 2, CYLINDER_BANDS + 1)
    profile = [*((radius, z) for z in heights), (0.0, height / 2)]
    faces = np.arange(TARGET_FACES).reshape(CYLINDER_BANDS + 1, CYLINDER_SECTORS)
    vertices, triangles, ids = revolve(np.array(profile), CYLINDER_SECTORS, faces)
    size = np.array([radius, height / 2, 0.0])
    solids = _solids([(CYLINDER, centre, np.eye(3), size)])
    mesh = (vertices + centre, triangles, ids)
    reach = math.hypot(radius, height / 2)
    return _target("cylinder", solids, mesh, middle=centre, radius=radius, reach=reach)


def _box(rng: np.random.Generator, extent: NDArray, gap: float, cap: float) -> Target:
    """Upright box turned about z, its 60 faces split between the sides and the top."""
    a, b = rng.uniform(0.3, 0.8, size=2)
    height = rng.uniform(1.0, cap)
    centre = np.array([*_place(rng, extent, math.hypot(a, b), gap), height / 2])
    rotation = matrix_from_euler_xyz(np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)]))
    half = np.array([a, b, height / 2])
    vertices, triangles, ids = _box_mesh(half)
    solids = _solids([(BOX, centre, rotation, half)])
    mesh = (vertices @ rotation.T + centre, triangles, ids)
    reach = float(np.linalg.norm(half))
    return _target("box", solids, mesh, middle=centre, radius=math.hypot(a, b), reach=reach)


def _sphere(rng: np.random.Generator, extent: NDArray, gap: float, cap: float) -> Target:
    """Sphere resting on the floor: 5 bands of equal height, so of equal area (Archimedes),
    by 12 sectors."""
    radius = rng.uniform(0.4, min(0.9, cap / 2))
    centre = np.array([*_place(rng, extent, radius, gap), radius])
    bands = np.arcsin(np.linspace(-1.0, 1.0, 6))
    latitude = np.concatenate(
        [np.linspace(lo, hi, 3, endpoint=False) for lo, hi in itertools.pairwise(bands)]
        + [bands[-1:]]
    )
    rho = radius * np.cos(latitude)
    rho[[0, -1]] = 0.0  # the poles
    faces = np.repeat(np.arange(TARGET_FACES).reshape(5, 12), 3, axis=0).repeat(2, axis=1)
    vertices, triangles, ids = revolve(np.column_stack([rho, radius * np.sin(latitude)]), 24, faces)
    solids = _solids([(SPHERE, centre, np.eye(3), np.array([radius, 0.0, 0.0]))])
    mesh = (vertices + centre, triangles, ids)
    return _target("sphere", solids, mesh, middle=centre, radius=radius, reach=radius)


def _t_pipe(rng: np.random.Generator, extent: NDArray, gap: float, cap: float) -> Target:
    """An upright pipe under a horizontal one, both of one radius (004 Sec V's T-shaped pipe).

    Faces: the upright's side 12 sectors x 2 bands (0-23); the cross pipe's ends, each in two
    halves (24, 25 and 58, 59), and its side 8 sectors x 4 lengths (26-57). The upright's
    radius (0.15-0.35 m) leaves it above 0.3 m below the joint (height >= 1 m).
    """
    radius, height = rng.uniform(0.15, 0.35), rng.uniform(1.0, cap)
    length = rng.uniform(1.0, 2.0)
    across = math.hypot(length / 2, radius)
    floor = np.array([*_place(rng, extent, across, gap), 0.0])
    yaw = rng.uniform(-math.pi, math.pi)
    axis_z = height - radius  # the cross pipe's axis; the upright ends there, inside it
    # Where the pipes meet, each hides part of the other: the upright's top strip (within
    # radius of the axis) joins its upper band, and the cross pipe's two middle lengths reach
    # past the upright, so that every face keeps a visible part.
    joint = axis_z - radius
    upright_faces = np.arange(24).reshape(2, 12)[[0, 1, 1]]
    heights = [0.0, joint / 2, joint, axis_z]
    upright = revolve(np.array([(radius, z) for z in heights]), 12, upright_faces)
    inner = (radius + length / 2) / 2
    along = [-length / 2, -inner, 0.0, inner, length / 2]
    profile = [(0.0, -length / 2), *((radius, z) for z in along), (0.0, length / 2)]
    cross_faces = np.vstack(
        [
            np.repeat([24, 25], 8),
            np.arange(26, 58).reshape(4, 8).repeat(2, 1),
            np.repeat([58, 59], 8),
        ]
    )
    cross = revolve(np.array(profile), 16, cross_faces)
    turn = matrix_from_euler_xyz(np.array([0.0, math.pi / 2, yaw]))  # local z: horizontal
    middle = floor + np.array([0.0, 0.0, axis_z])
    mesh = _joined([(upright[0] + floor, *upright[1:]), (cross[0] @ turn.T + middle, *cross[1:])])
    solids = _solids(
        [
            (
                CYLINDER,
                floor + np.array([0.0, 0.0, axis_z / 2]),
                np.eye(3),
                np.array([radius, axis_z / 2, 0.0]),
            ),
            (CYLINDER, middle, turn, np.array([radius, length / 2, 0.0])),
        ]
    )
    box = _bound(solids)
    reach = float(np.linalg.norm(box[1] - box[0]) / 2)
    return _target("t-pipe", solids, mesh, middle=box.mean(axis=0), radius=across, reach=reach)


def revolve(profile: NDArray[np.float64], around: int, faces: NDArray[np.int64]) -> Mesh:
    """A surface of revolution about the local z axis, as (vertices, triangles, face ids).

    ``profile`` holds (radius, z) points, walked with the solid's inside on the left (up a
    side, inward over a top, outward under a bottom), so that the triangles face outward; a
    point of radius 0 is one vertex (a pole or a cap's centre). ``faces`` gives the face id
    of each (profile segment, one of ``around`` columns).
    """
    angles = np.linspace(0.0, 2.0 * math.pi, around, endpoint=False)
    circle = np.column_stack([np.cos(angles), np.sin(angles)])
    rings, first, count = [], [], 0
    for rho, z in profile:
        first.append(count)
        ring = (
            np.array([[0.0, 0.0, z]])
            if rho == 0.0
            else np.column_stack([rho * circle[:, 0], rho * circle[:, 1], np.full(around, z)])
        )
        rings.append(ring)
        count += len(ring)
    columns = np.arange(around)
    tris, ids = [], []
    for i in range(len(profile) - 1):
        lower, upper = profile[i, 0] != 0.0, profile[i + 1, 0] != 0.0
        a = first[i] + columns * lower
        b = first[i] + (columns + 1) % around * lower
        c = first[i + 1] + columns * upper
        d = first[i + 1] + (columns + 1) % around * upper
        pair = [np.column_stack(t) for t, keep in (((a, b, d), lower), ((a, d, c), upper)) if keep]
        tris.append(np.stack(pair, axis=1).reshape(-1, 3))
        ids.append(np.repeat(faces[i], len(pair)))
    vertices = np.vstack(rings).astype(np.float64)
    return vertices, np.vstack(tris).astype(np.int64), np.concatenate(ids).astype(np.int64)


#: Ways to split a box's 60 faces: rows on each side (of 3 columns) and the top's grid.
_BOX_SPLITS = ((2, (6, 6)), (3, (6, 4)), (4, (4, 3)))


def _box_mesh(half: NDArray[np.float64]) -> Mesh:
    """The sides (3 columns each) and the top of a box, floor left open; of the splits of
    ``_BOX_SPLITS`` the one whose faces' areas differ least (tall boxes: more rows)."""
    a, b, h = 2.0 * half

    def spread(split: tuple[int, tuple[int, int]]) -> float:
        rows, (n, m) = split
        areas = (a * h / (3 * rows), b * h / (3 * rows), a * b / (n * m))
        return max(areas) / min(areas)

    rows, (n, m) = min(_BOX_SPLITS, key=spread)
    up = np.array([0.0, 0.0, h])
    parts = []
    for side, normal in enumerate(np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])):
        across = np.cross([0.0, 0.0, 1.0], normal) * (2.0 * half)  # normal = across x up
        corner = normal * half - across / 2 - up / 2
        parts.append(_grid(corner, across, up, (3, rows), 3 * rows * side))
    top_counts = (n, m) if a >= b else (m, n)  # more columns along the longer edge
    top = _grid(-half * (1, 1, -1), np.array([a, 0, 0]), np.array([0, b, 0]), top_counts, 12 * rows)
    return _joined([*parts, top])


def _grid(
    corner: NDArray, u: NDArray, v: NDArray, counts: tuple[int, int], first_face: int
) -> Mesh:
    """A parallelogram of ``counts`` (along u, along v) faces, two triangles each, facing u x v."""
    nu, nv = counts
    s, t = np.meshgrid(np.linspace(0.0, 1.0, nu + 1), np.linspace(0.0, 1.0, nv + 1))
    vertices = corner + s.reshape(-1, 1) * u + t.reshape(-1, 1) * v
    col, row = np.meshgrid(np.arange(nu), np.arange(nv))
    a = (row * (nu + 1) + col).ravel()
    b, c = a + 1, a + nu + 1
    triangles = np.vstack([np.column_stack([a, b, c + 1]), np.column_stack([a, c + 1, c])])
    ids = np.tile(first_face + (row * nu + col).ravel(), 2)
    return vertices, triangles.astype(np.int64), ids.astype(np.int64)


def _joined(meshes: list[Mesh]) -> Mesh:
    """Several meshes as one, triangles re-indexed."""
    base = np.cumsum([0] + [len(m[0]) for m in meshes[:-1]])
    return (
        np.vstack([m[0] for m in meshes]),
        np.vstack([m[1] + b for m, b in zip(meshes, base, strict=True)]),
        np.concatenate([m[2] for m in meshes]),
    )


def _solids(rows: list[tuple[int, NDArray, NDArray, NDArray]]) -> Solids:
    return Solids(
        kind=np.array([r[0] for r in rows], dtype=np.int8),
        centre=np.array([r[1] for r in rows], dtype=np.float64),
        rotation=np.array([r[2] for r in rows], dtype=np.float64),
        size=np.array([r[3] for r in rows], dtype=np.float64),
    )


def _bound(solids: Solids) -> NDArray[np.float64]:
    boxes = [
        solid_bounds(int(k), solids.centre[i], solids.rotation[i], solids.size[i])
        for i, k in enumerate(solids.kind)
    ]
    return np.stack([np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)])


def _target(
    shape: TargetShape, solids: Solids, mesh: Mesh, *, middle: NDArray, radius: float, reach: float
) -> Target:
    vertices, triangles, faces = mesh
    return Target(shape, solids, vertices, triangles, faces, _bound(solids), middle, reach, radius)
