"""Rooms of 004 Sec III-E: exact clearance to primitives, and seeded sampling."""

import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.rooms import (
    BOX,
    CYLINDER,
    SPHERE,
    TARGET_FACES,
    Solids,
    clearance,
    sample_room,
    side_by_side,
    stack_solids,
)

ROOM = np.array([10.0, 10.0, 4.0])
CENTRE = np.array([5.0, 5.0, 2.0])


def _one(kind: int, size, rotation=None) -> Solids:
    return Solids(
        kind=np.array([kind], dtype=np.int8),
        centre=CENTRE[None],
        rotation=(np.eye(3) if rotation is None else np.asarray(rotation))[None],
        size=np.asarray(size, dtype=float)[None],
    )


def test_box_clearance_outside_inside_and_at_a_corner():
    solids = _one(BOX, [1.0, 0.5, 0.25])
    points = CENTRE + np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.3, 0.9, 0.25]])
    expected = [1.0, -0.25, 0.5]  # face, inside (nearest face is z), edge: hypot(0.3, 0.4)
    np.testing.assert_allclose(clearance(points, solids, ROOM), expected, atol=1e-12)


def test_cylinder_clearance_follows_its_rotated_axis():
    # local z along world y: the axis lies on y, the radius spans x and z
    to_y = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    solids = _one(CYLINDER, [0.5, 1.0, 0.0], to_y)
    points = CENTRE + np.array([[0.0, 1.75, 0.0], [1.5, 0.0, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(clearance(points, solids, ROOM), [0.75, 1.0, 0.5], atol=1e-12)


def test_sphere_and_walls():
    solids = _one(SPHERE, [1.0, 0.0, 0.0])
    points = np.array([CENTRE + np.array([0.0, 0.0, 1.5]), [0.3, 5.0, 2.0], [9.0, 9.0, 3.9]])
    np.testing.assert_allclose(clearance(points, solids, ROOM), [0.5, 0.3, 0.1], atol=1e-12)


def test_batched_rooms_use_their_own_solids():
    a, b = _one(SPHERE, [1.0, 0, 0]), _one(SPHERE, [0.5, 0, 0])
    rooms = [sample_room(np.random.default_rng(0), 0), sample_room(np.random.default_rng(1), 0)]
    stacked = stack_solids(rooms)
    assert stacked.kind.shape == (2, 1)
    both = Solids(
        np.stack([a.kind, b.kind]),
        np.stack([a.centre, b.centre]),
        np.stack([a.rotation, b.rotation]),
        np.stack([a.size, b.size]),
    )
    gaps = clearance(np.tile(CENTRE + np.array([2.0, 0, 0]), (2, 1)), both, ROOM)
    np.testing.assert_allclose(gaps, [1.0, 1.5])


@pytest.mark.parametrize("obstacles", [0, 9])
def test_sampled_rooms_are_seeded_and_start_clear(obstacles):
    first = sample_room(np.random.default_rng(3), obstacles)
    again = sample_room(np.random.default_rng(3), obstacles)
    other = sample_room(np.random.default_rng(4), obstacles)
    assert first.obstacle_count == obstacles
    np.testing.assert_array_equal(first.vertices, again.vertices)
    assert not np.array_equal(first.start, other.start)
    assert sorted(set(first.face_of_triangle[first.face_of_triangle >= 0])) == list(
        range(TARGET_FACES)
    )
    if obstacles == 0:
        assert clearance(first.start[None], first.solids, first.size)[0] >= 0.6
    assert -math.pi <= first.start_yaw <= math.pi


def test_bad_rooms_are_refused():
    with pytest.raises(InvalidInputError, match="obstacle count"):
        sample_room(np.random.default_rng(0), -1)
    with pytest.raises(InvalidInputError, match="at least 4 x 4 x 2"):
        sample_room(np.random.default_rng(0), 0, size=(3.0, 10.0, 4.0))


def test_rooms_side_by_side_keep_their_own_triangles_and_faces():
    rooms = [sample_room(np.random.default_rng(seed), 2) for seed in (0, 1)]
    vertices, triangles, faces = side_by_side(rooms, 12.0)
    first = len(rooms[0].vertices)
    np.testing.assert_array_equal(vertices[first:], rooms[1].vertices + np.array([12.0, 0.0, 0.0]))
    np.testing.assert_array_equal(triangles[len(rooms[0].triangles) :], rooms[1].triangles + first)
    np.testing.assert_array_equal(faces, np.concatenate([r.face_of_triangle for r in rooms]))
    batch = stack_solids(rooms)
    one = batch.rows(np.array([1]))
    np.testing.assert_array_equal(one.centre[0, :3], rooms[1].solids.centre)
