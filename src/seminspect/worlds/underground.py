"""Underground worlds with rough rock walls.

* ``subterranean``: the 10 m x 6 m x 4 m tunnel section with one car of 000 Sec VI-C.
* ``mine-drift``: a 5 m wide, 4.5 m high drift ending in a rock face, the routine-inspection
  site of 002 Sec IV-V. The ``historical`` scenario is the site as first mapped; ``current`` is
  the same site (same seed, same rock) after mining: the face has receded by up to
  ``recession`` metres in its middle and a fallen boulder lies in the drift. Planning on one and
  flying in the other reproduces the model/site discrepancy 002 adapts to.

Rock surfaces are grids displaced along their normal by a smooth random relief that fades to
zero at their borders, so walls, roof and face meet without gaps.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.shapes import Piece, pose_matrix, sphere
from seminspect.worlds.vehicles import vehicle_pieces
from seminspect.worlds.world import World

TUNNEL_SIZE = (10.0, 6.0, 4.0)
DRIFT_WIDTH = 5.0
DRIFT_HEIGHT = 4.5


Relief = Callable[[NDArray, NDArray], NDArray]


def _relief(rng: np.random.Generator, amplitude: float, waves: int = 6) -> Relief:
    """A smooth random height field: a sum of plane waves 1-4 m long."""
    angles = rng.uniform(0.0, math.tau, waves)
    lengths = rng.uniform(1.0, 4.0, waves)
    phases = rng.uniform(0.0, math.tau, waves)
    k = np.column_stack([np.cos(angles), np.sin(angles)]) * (math.tau / lengths)[:, None]

    def height(u: NDArray, v: NDArray) -> NDArray:
        total = np.zeros_like(u)
        for (ku, kv), phase in zip(k, phases, strict=True):
            total += np.cos(ku * u + kv * v + phase)
        return amplitude * total / math.sqrt(waves / 2)

    return height


def rock_surface(
    corner: ArrayLike,
    axis_u: ArrayLike,
    axis_v: ArrayLike,
    inward: ArrayLike,
    *,
    relief: Relief,
    step: float = 0.25,
    extra: Relief | None = None,
) -> tuple[NDArray, NDArray]:
    """A rough rectangle ``corner + u*axis_u + v*axis_v`` with normals facing ``inward``.

    ``relief(u, v)`` (and ``extra(u, v)``) displace points along ``-inward`` (into the rock);
    both are scaled by a taper that vanishes on the rectangle's border.
    """
    au, av, n = (np.asarray(a, dtype=np.float64) for a in (axis_u, axis_v, inward))
    size_u, size_v = float(np.linalg.norm(au)), float(np.linalg.norm(av))
    nu, nv = max(2, math.ceil(size_u / step)), max(2, math.ceil(size_v / step))
    u, v = np.meshgrid(
        np.linspace(0, size_u, nu + 1), np.linspace(0, size_v, nv + 1), indexing="ij"
    )
    taper = np.sin(math.pi * u / size_u) * np.sin(math.pi * v / size_v)
    depth = relief(u, v) * taper + (extra(u, v) if extra else 0.0) * taper
    points = (
        np.asarray(corner, dtype=np.float64)
        + u[..., None] * au / size_u
        + v[..., None] * av / size_v
        - depth[..., None] * n
    ).reshape(-1, 3)
    index = np.arange((nu + 1) * (nv + 1)).reshape(nu + 1, nv + 1)
    a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
    c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    faces = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    if np.dot(np.cross(au, av), n) < 0:
        faces = faces[:, ::-1]
    return points, faces


def _tunnel(
    builder: WorldBuilder,
    rng: np.random.Generator,
    size: tuple[float, float, float],
    amplitude: float,
) -> None:
    """Floor, two rough side walls and a rough roof along +x from x = 0 to ``size[0]``."""
    length, width, height = size
    builder.add_ground((0.0, 0.0), (length, width))
    surfaces = [
        ((0, 0, 0), (length, 0, 0), (0, 0, height), (0, 1, 0)),
        ((0, width, 0), (length, 0, 0), (0, 0, height), (0, -1, 0)),
        ((0, 0, height), (length, 0, 0), (0, width, 0), (0, 0, -1)),
    ]
    for corner, au, av, inward in surfaces:
        points, faces = rock_surface(corner, au, av, inward, relief=_relief(rng, amplitude))
        builder.add_faces(points, faces, "wall")


def generate_subterranean(seed: int) -> World:
    """The tunnel section with a car in its middle."""
    rng = make_rng(seed, "worlds", "subterranean")
    length, width, _ = TUNNEL_SIZE
    builder = WorldBuilder("subterranean", seed)
    _tunnel(builder, rng, TUNNEL_SIZE, amplitude=0.08)
    builder.add_object(vehicle_pieces("car"), "car", pose_matrix((length / 2, width / 2, 0.0)))
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), TUNNEL_SIZE],
        start_position=(1.0, width / 2, 0.0),
        start_yaw=0.0,
        metadata={"ground_z": 0.0},
    )


def generate_mine_drift(
    scenario: str,
    seed: int,
    length: float = 40.0,
    recession: float = 1.0,
    obstacle: bool = True,
) -> World:
    """The drift as first mapped (``historical``) or after mining (``current``)."""
    if not (0.0 <= recession <= 3.0):
        raise InvalidInputError(f"face recession must be 0-3 m, got {recession}")
    current = scenario == "current"
    rocks = []
    if current and obstacle:
        rocks.append(sphere(0.7, "rock").transformed(pose_matrix((0.7 * length, 1.3, 0.5))))
    return drift_world(seed, length, recession=recession, cut_face=current, rocks=rocks)


def drift_world(
    seed: int,
    length: float,
    *,
    recession: float = 0.0,
    cut_face: bool = True,
    face_advance: float = 0.0,
    rocks: Sequence[Piece] = (),
) -> World:
    """The drift of ``seed`` (the same rock for every variant) with its face cut back by a
    bowl up to ``recession`` deep (when ``cut_face``; the bounds leave room for it either way),
    moved ``face_advance`` metres towards the portal, and
    ``rocks`` (each a separate ``rock`` object) added: the variants routine inspection meets."""
    if not (10.0 <= length <= 200.0):
        raise InvalidInputError(f"mine drift length must be 10-200 m, got {length}")
    if not (0.0 <= face_advance <= 0.5 * length):
        raise InvalidInputError(f"face advance must be 0-{0.5 * length:g} m, got {face_advance}")
    rng = make_rng(seed, "worlds", "mine-drift", "rock")
    builder = WorldBuilder("mine-drift", seed)
    _tunnel(builder, rng, (length, DRIFT_WIDTH, DRIFT_HEIGHT), amplitude=0.12)

    def mined(u: NDArray, v: NDArray) -> NDArray:
        # A bowl cut into the middle of the face, deepest at its centre.
        return recession * np.exp(-((u - DRIFT_WIDTH / 2) ** 2 + (v - 2.0) ** 2) / (2 * 0.9**2))

    face_x = length - face_advance
    points, faces = rock_surface(
        (face_x, 0.0, 0.0),
        (0.0, DRIFT_WIDTH, 0.0),
        (0.0, 0.0, DRIFT_HEIGHT),
        (-1.0, 0.0, 0.0),
        relief=_relief(rng, 0.25),
        extra=mined if cut_face and recession > 0 else None,
    )
    face = builder.new_instance("rock-face")
    builder.add_faces(points, faces, "rock-face", "face", face)
    for rock in rocks:
        builder.add_object([rock], "rock")
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), (length + recession + 1.0, DRIFT_WIDTH, DRIFT_HEIGHT)],
        start_position=(2.0, DRIFT_WIDTH / 2, 0.0),
        start_yaw=0.0,
        metadata={"ground_z": 0.0, "face_x": face_x, "recession": recession if cut_face else 0.0},
    )


def mine_drift_pair(seed: int = 0, **options) -> tuple[World, World]:
    """The ``historical`` and ``current`` drift of one seed, for change-aware inspection."""
    return (
        generate_mine_drift("historical", seed, **options),
        generate_mine_drift("current", seed, **options),
    )
