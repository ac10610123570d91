"""Rooms of 004 Sec III-E: exact clearance to primitives, and seeded sampling."""

import hashlib
import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.env_config import PAPER_ROOM_RANGE, TARGET_SHAPES, EnvConfig
from seminspect.missions.learning.rooms import (
    BOX,
    CYLINDER,
    SPHERE,
    SURFACES,
    TARGET_FACES,
    Solids,
    clearance,
    sample_room,
    side_by_side,
    stack_solids,
    struck_surface,
)
from seminspect.missions.learning.solids import solid_distance, surface_gap

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
        sample_room(np.random.default_rng(0), 0, EnvConfig(room_size=(3.0, 10.0, 4.0)))


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


def _fingerprint(room) -> str:
    """Every number of a room, rounded to 1e-9 (robust to a last-bit difference in libm)."""
    digest = hashlib.sha256()
    for values in (
        room.size,
        room.solids.centre,
        room.solids.rotation,
        room.solids.size,
        room.vertices,
        room.start,
        [room.start_yaw],
    ):
        digest.update((np.round(np.asarray(values, dtype=np.float64), 9) + 0.0).tobytes())
    for values in (room.solids.kind, room.triangles, room.face_of_triangle):
        digest.update(np.asarray(values, dtype=np.int64).tobytes())
    return digest.hexdigest()[:16]


#: (seed, obstacles): fingerprint and the generator's next draw, from the code policy v1 was
#: trained with (sample_room(rng, obstacles) at commit 7573911).
POLICY_V1_ROOMS = {
    (0, 0): ("7ce7e86d7879964a", 0.772649201225),
    (1, 9): ("0e9074d17ccd801b", 0.786794760939),
    (2, 19): ("d4ad001ba0f0418b", 0.629093521066),
    (3, 4): ("b4e378e8a2aab566", 0.134680167786),
}


@pytest.mark.parametrize(("seed", "obstacles"), list(POLICY_V1_ROOMS))
def test_legacy_rooms_are_those_policy_v1_was_trained_in(seed, obstacles):
    rng = np.random.default_rng(seed)
    room = sample_room(rng, obstacles, EnvConfig.legacy())
    fingerprint, next_draw = POLICY_V1_ROOMS[seed, obstacles]
    assert _fingerprint(room) == fingerprint
    assert rng.random() == pytest.approx(next_draw, abs=1e-12)  # the same draws, no more
    assert room.shape == "cylinder" and room.target_solids == 1


def test_rooms_draw_their_size_from_the_range_and_their_shape_from_the_list():
    config = EnvConfig(room_size_range=PAPER_ROOM_RANGE, target_shapes=TARGET_SHAPES)
    rooms = [sample_room(np.random.default_rng(seed), 4, config) for seed in range(40)]
    sizes = np.array([room.size for room in rooms])
    low, high = np.array(PAPER_ROOM_RANGE).T
    assert np.all((sizes >= low) & (sizes <= high))
    assert np.all(sizes.std(axis=0) > 0.2 * (high - low))  # spread over the range
    assert {room.shape for room in rooms} == set(TARGET_SHAPES)
    for room in rooms:
        assert np.all(room.target_box[0] >= 0.0) and np.all(room.target_box[1] <= room.size)
        assert room.obstacle_count == 4
        assert room.target_solids == (2 if room.shape == "t-pipe" else 1)
        assert clearance(room.start[None], room.solids, room.size)[0] > 0.2


def _dense_surface(solids, i, rng, count=8_000):
    """Random points on the surface of solid ``i``, independent of the rule's own samples."""
    kind, size = int(solids.kind[i]), solids.size[i]
    if kind == BOX:
        points = rng.uniform(-1.0, 1.0, (count, 3))
        points[np.arange(count), rng.integers(3, size=count)] = rng.choice([-1.0, 1.0], count)
        points *= size
    elif kind == CYLINDER:
        angle, z = rng.uniform(0, 2 * math.pi, count), rng.uniform(-1.0, 1.0, count)
        rho = np.where(rng.random(count) < 0.7, 1.0, np.sqrt(rng.random(count)))
        z = np.where(rho < 1.0, np.sign(z), z)  # caps
        points = np.column_stack([rho * np.cos(angle), rho * np.sin(angle), z])
        points *= (size[0], size[0], size[1])
    else:
        points = rng.normal(size=(count, 3))
        points *= size[0] / np.linalg.norm(points, axis=1, keepdims=True)
    return points @ solids.rotation[i].T + solids.centre[i]


def _rooms(rule, obstacles, seeds, shapes=("cylinder",)):
    config = EnvConfig(obstacle_rule=rule, target_shapes=shapes)
    return [sample_room(np.random.default_rng(seed), obstacles, config) for seed in seeds]


def _dense_nearest_gap(room, rng, within=0.6):
    """The target's gap to its nearest obstacle by dense sampling both ways, among the
    obstacles whose bounding sphere comes ``within`` of the target's bound (inf: none)."""
    solids, n = room.solids, room.target_solids
    target = solids.rows(np.arange(n))
    middle, reach = room.target_box.mean(axis=0), np.linalg.norm(np.ptp(room.target_box, 0)) / 2
    nearest = np.inf
    for i in range(n, len(solids.kind)):
        if (
            np.linalg.norm(solids.centre[i] - middle) - np.linalg.norm(solids.size[i])
            > reach + within
        ):
            continue
        obstacle = solids.rows(np.array([i]))
        out = solid_distance(_dense_surface(solids, i, rng), target).min()
        back = min(solid_distance(_dense_surface(target, j, rng), obstacle).min() for j in range(n))
        nearest = min(nearest, out, back)
    return nearest


def _nearest_gaps(rooms):
    """Per room, the gap between the target and its nearest obstacle (the rule's measure)."""
    return np.array(
        [
            min(
                surface_gap(
                    room.solids.rows(np.array([i])), room.solids.rows(np.arange(room.target_solids))
                )
                for i in range(room.target_solids, len(room.solids.kind))
            )
            for room in rooms
        ]
    )


def test_the_surface_rule_leaves_the_robots_width_and_comes_nearer_than_v1s():
    robot, rng = EnvConfig().robot_radius, np.random.default_rng(0)
    gaps = [
        _dense_nearest_gap(room, rng) for room in _rooms("surface", 19, range(6), TARGET_SHAPES)
    ]
    assert min(gaps) >= 2 * robot - 5e-3  # dense samples: within a few mm of exact
    assert min(gaps) < 2 * robot + 0.15  # and some obstacle does come that close
    near = _nearest_gaps(_rooms("surface", 9, range(30)))
    legacy = _nearest_gaps(_rooms("target-sphere", 9, range(30)))
    assert np.median(near) < np.median(legacy) - 0.2


def _apart(room, points, but=None, margin=0.3):
    """The points at least ``margin`` from every solid other than ``but`` and from the walls."""
    others = [j for j in range(len(room.solids.kind)) if j != but]
    gaps = [solid_distance(points, room.solids.rows(slice(j, j + 1))) for j in others]
    walls = np.minimum(points, room.size - points).min(axis=1)
    return points[np.minimum.reduce([walls, *gaps]) > margin]


def test_a_crash_is_put_on_the_surface_it_struck():
    rng = np.random.default_rng(0)
    room = sample_room(np.random.default_rng(3), 9, EnvConfig(target_shapes=("t-pipe",)))
    assert room.target_solids == 2  # the T-pipe's trunk and arm both count as the object
    for i in range(len(room.solids.kind)):
        near = _apart(room, _dense_surface(room.solids, i, rng, 2_000), but=i)
        expected = "object" if i < room.target_solids else "obstacle"
        assert len(near) > 0, f"solid {i} has no surface clear of the rest"
        assert {struck_surface(room, p) for p in near[:25]} == {expected}
    size = room.size
    for name, fixed_axis, value in (
        ("floor", 2, 0.05), ("ceiling", 2, size[2] - 0.05), ("wall", 0, 0.05),
        ("wall", 1, size[1] - 0.05),
    ):  # fmt: skip
        points = rng.uniform((0.4, 0.4, 0.4), size - 0.4, (400, 3))
        points[:, fixed_axis] = value
        clear = [p for p in points if solid_distance(p[None], room.solids)[0] > 0.3]
        assert clear and {struck_surface(room, p) for p in clear[:25]} == {name}
    assert set(SURFACES) == {"wall", "floor", "ceiling", "object", "obstacle"}
