"""Feasible target faces under the strict rule: sampled free, visible, level, large viewpoints."""

import dataclasses

import numpy as np
import pytest
from numpy.typing import NDArray

from seminspect.core.rng import make_rng
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.feasibility import face_geometry, feasible_faces
from seminspect.missions.learning.rooms import BOX, TARGET_FACES, Room, Solids, sample_room
from seminspect.worlds.shapes import box

#: A cylinder's 12 sectors x 4 bands: faces 0..47 are its side, 48..59 its top.
SECTORS, BANDS = 12, 4
SIDE = SECTORS * BANDS
CONFIG = EnvConfig()


@pytest.fixture(scope="module")
def empty_room() -> Room:
    return sample_room(make_rng(3, "test", "feasibility"), 0)


def _with_box(room: Room, lower, upper) -> Room:
    """``room`` with one more axis-aligned box, as a solid and as triangles."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    piece = box(lower, upper)
    solids = room.solids
    extra = Solids(
        kind=np.append(solids.kind, np.int8(BOX)),
        centre=np.vstack([solids.centre, (lower + upper) / 2]),
        rotation=np.concatenate([solids.rotation, np.eye(3)[None]]),
        size=np.vstack([solids.size, (upper - lower) / 2]),
    )
    return dataclasses.replace(
        room,
        solids=extra,
        vertices=np.vstack([room.vertices, piece.vertices]),
        triangles=np.vstack([room.triangles, piece.faces + len(room.vertices)]),
        face_of_triangle=np.concatenate([room.face_of_triangle, np.full(len(piece.faces), -1)]),
    )


def _sector_zero(room: Room) -> NDArray:
    """The side faces facing +x (normals within 26 deg of it)."""
    _, normal, _ = face_geometry(room)
    return np.flatnonzero(normal[:, 0] > 0.9)


def test_face_geometry_gives_outward_normals_and_the_cylinders_areas(empty_room):
    centre, normal, area = face_geometry(empty_room)
    axis = empty_room.solids.centre[0]
    radius, half = empty_room.solids.size[0, :2]
    radial = (centre[:SIDE] - axis)[:, :2]
    assert np.all(np.einsum("ij,ij->i", radial, normal[:SIDE, :2]) > 0)  # outward
    np.testing.assert_allclose(normal[SIDE:], np.tile([0.0, 0.0, 1.0], (SECTORS, 1)))
    chord = 2 * radius * np.sin(np.pi / SECTORS)
    np.testing.assert_allclose(area[:SIDE], chord * 2 * half / BANDS)
    assert area[SIDE:].sum() == pytest.approx(0.5 * SECTORS * radius**2 * np.sin(np.pi / 6))


def test_in_an_empty_room_the_side_is_feasible_and_the_top_is_not(empty_room):
    feasible = feasible_faces(empty_room, CONFIG)
    assert feasible.shape == (TARGET_FACES,)
    assert feasible[:SIDE].all()
    # A level camera sees a face within 60 deg of "up" only >= 30 deg below the horizon, far
    # outside the focus rows (+-15.5 deg for a 58 deg vertical field of view).
    assert not feasible[SIDE:].any()


def test_a_grazing_incidence_limit_lets_the_top_in(empty_room):
    grazing = EnvConfig(strict_incidence_deg=89.0, strict_min_pixels=1)
    assert feasible_faces(empty_room, grazing)[SIDE:].any()


def test_faces_walled_in_by_a_box_or_hidden_behind_a_wall_are_infeasible(empty_room):
    cx, cy, _ = empty_room.solids.centre[0]
    radius = empty_room.solids.size[0, 0]
    front = _sector_zero(empty_room)
    assert len(front) == 2 * BANDS  # sectors 0 and 11, 15 deg either side of +x
    # flush against the +x side: no free viewpoint in front of it
    walled = _with_box(empty_room, (cx + radius + 0.05, cy - 2.5, 0.0), (10.0, cy + 2.5, 4.0))
    feasible = feasible_faces(walled, CONFIG)
    assert not feasible[front].any()
    assert feasible[_opposite(empty_room)].all()
    # a thin wall 0.3 m off the side: the viewpoints behind it are free but cannot see it
    hidden = _with_box(empty_room, (cx + radius + 0.3, 0.0, 0.0), (cx + radius + 0.4, 10.0, 4.0))
    assert not feasible_faces(hidden, CONFIG)[front].any()


def _opposite(room: Room) -> NDArray:
    _, normal, _ = face_geometry(room)
    return np.flatnonzero(normal[:, 0] < -0.9)


def test_a_face_too_small_in_the_image_is_infeasible(empty_room):
    assert not feasible_faces(empty_room, EnvConfig(strict_min_pixels=5000)).any()


def test_the_answer_follows_the_seed_and_is_repeatable():
    room = sample_room(make_rng(5, "test", "feasibility"), 19)
    first = feasible_faces(room, CONFIG, seed=1)
    np.testing.assert_array_equal(first, feasible_faces(room, CONFIG, seed=1))
    assert first[:SIDE].sum() > SIDE // 2  # cluttered, yet most of the side stays inspectable
