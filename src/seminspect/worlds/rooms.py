"""Rooms with primitive obstacles and one semantic target, as in 004 Sec III-E.

The room's length and width are drawn from [4, 20] m and its height from [2, 8] m; boxes,
cylinders and spheres of random size are scattered with random positions and orientations, and
one ``target`` object (a 15-sided cylinder: N_f = 60 faces, as in 004 Sec III-D) stands on the
floor. The scenarios ``0``, ``4``, ``9``, ``14`` and ``19`` are the obstacle counts of 004 Table I.
"""

from __future__ import annotations

import math

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.shapes import Piece, box, cylinder, pose_matrix, sphere
from seminspect.worlds.world import World

SCENARIOS = {str(n): n for n in (0, 4, 9, 14, 19)}


def _primitive(rng: np.random.Generator) -> Piece:
    kind = rng.integers(3)
    size = rng.uniform(0.3, 1.5, size=3)
    if kind == 0:
        return box(-size / 2, size / 2, "")
    if kind == 1:
        return cylinder(size[0] / 2, size[2], "")
    return sphere(size[0] / 2, "")


def _add_shell(builder: WorldBuilder, length: float, width: float, height: float) -> None:
    """Four walls and a ceiling as single surfaces facing into the room (class ``wall``)."""
    footprint = [(0.0, 0.0), (length, 0.0), (length, width), (0.0, width)]
    corners = np.array([(x, y, z) for z in (0.0, height) for x, y in footprint])
    quads = [(0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0), (4, 7, 6, 5)]
    faces = [tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))]
    builder.add_faces(corners, faces, "wall")


def _spot(rng: np.random.Generator, length: float, width: float, keep_away: np.ndarray):
    """A floor position preferably 1.6 m (in plan) from the start and the target.

    Tiny rooms may have no such place; then the candidate farthest from both is used.
    """
    candidates = rng.uniform((0.5, 0.5), (length - 0.5, width - 0.5), size=(64, 2))
    margin = np.min(np.linalg.norm(candidates[:, None] - keep_away[None], axis=2), axis=1)
    good = np.flatnonzero(margin >= 1.6)
    return candidates[good[0] if len(good) else int(np.argmax(margin))]


def generate_room(scenario: str, seed: int) -> World:
    """A room with ``int(scenario)`` obstacles and one target."""
    rng = make_rng(seed, "worlds", "room")
    length, width = rng.uniform(4.0, 20.0, size=2)
    height = rng.uniform(2.0, 8.0)
    builder = WorldBuilder("room", seed)
    builder.add_ground((0.0, 0.0), (length, width))
    _add_shell(builder, length, width, height)
    target = cylinder(0.4, 1.0, "", sections=15)
    tx, ty = rng.uniform(1.0, length - 1.0), rng.uniform(1.0, width - 1.0)
    builder.add_object([target], "target", pose_matrix((tx, ty, 0.5)))
    start = (min(1.0, length / 4), width / 2, 0.0)
    keep_away = np.array([start[:2], (tx, ty)])
    for _ in range(SCENARIOS[scenario]):
        centre = _spot(rng, length, width, keep_away)
        z = rng.uniform(0.3, height - 0.3)
        angles = rng.uniform(-math.pi, math.pi, size=3)
        builder.add_object(
            [_primitive(rng)], "obstacle", pose_matrix((*centre, z), euler_xyz=angles)
        )
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), (length, width, height)],
        start_position=start,
        start_yaw=0.0,
        metadata={"ground_z": 0.0, "target_faces": 60},
    )
