"""The 004 sensors: unit body-frame rays, the focus area, the mapping pixels, range noise and
the camera pixels culled against the target's bound."""

import math

import numpy as np
import pytest

from seminspect.geometry.transforms import rotate_xy
from seminspect.missions.learning.env_config import TARGET_SHAPES, EnvConfig
from seminspect.missions.learning.rooms import sample_room, side_by_side
from seminspect.missions.learning.sensors import (
    camera_rays,
    focus_mask,
    lidar_rays,
    mapping_pixels,
    noisy_ranges,
    sensor_rays,
)
from seminspect.worlds.raycast import RayCaster


def test_camera_rays_are_unit_and_look_forward_across_the_field_of_view():
    rays, cosines = camera_rays((96, 54), (87.0, 58.0))
    assert rays.shape == (96 * 54, 3)
    np.testing.assert_allclose(np.linalg.norm(rays, axis=1), 1.0, rtol=1e-6)
    np.testing.assert_array_equal(cosines, rays[:, 0])
    first, last = rays[0], rays[-1]  # top left, bottom right pixel
    assert first[1] > 0 and first[2] > 0 and last[1] < 0 and last[2] < 0
    half_width = np.degrees(np.arctan2(first[1], first[0]))
    assert 42.0 < half_width < 43.5  # pixel centres inside the 87 deg field of view


def test_lidar_rays_cover_the_circle_and_90_degrees_of_elevation():
    rays = lidar_rays((32, 8))
    assert rays.shape == (256, 3)
    np.testing.assert_allclose(np.linalg.norm(rays, axis=1), 1.0, rtol=1e-6)
    np.testing.assert_allclose(np.degrees(np.arcsin(rays[:, 2])).max(), 45.0, rtol=1e-5)


def test_focus_and_mapping_pixels():
    focus = focus_mask((8, 4)).reshape(4, 8)
    assert focus.sum() == 8 and focus[1:3, 2:6].all()
    mapped = mapping_pixels((6, 6)).reshape(6, 6)
    assert np.array_equal(np.argwhere(mapped), [[1, 1], [1, 4], [4, 1], [4, 4]])


def test_range_noise_grows_with_range_and_keeps_misses():
    distance = np.array([1.0, 9.0, 9.99, np.inf])
    noise = np.array([1.0, 1.0, 1.0, 1.0])
    noisy = noisy_ranges(distance, noise, (0.005, 0.01), 10.0)
    np.testing.assert_allclose(noisy[:2], [1.0 + 0.015, 9.0 + 0.095])
    assert noisy[2] == 10.0 and noisy[3] == np.inf  # clipped to the range; a miss stays one


def _kept_pixels(origin, yaw, camera, box, reach=10.0):
    lidar = lidar_rays((4, 2))
    mapped = np.zeros(len(camera), dtype=bool)
    rows, ray, _, _ = sensor_rays(
        origin[None],
        np.array([yaw]),
        camera,
        lidar,
        mapped,
        np.asarray(box, dtype=np.float64)[None],
        reach,
    )
    assert np.all(rows == 0) and np.sum(ray >= len(camera)) == len(lidar)  # every beam
    return set(ray[ray < len(camera)].tolist())


def test_pixels_are_culled_by_the_slab_test_on_the_target_box():
    box = [[4.0, -0.5, 0.0], [5.0, 0.5, 2.0]]
    camera = np.array(
        [
            [1.0, 0.0, 0.0],  # straight at the box
            [-1.0, 0.0, 0.0],  # away from it
            [0.0, 1.0, 0.0],  # parallel to its x faces, beside it
            [0.6, 0.0, 0.8],  # well over it
            [0.9, 0.0, 0.2],  # rising: meets its near face at z = 1.89
            [0.9, 0.0, 0.26],  # rising: passes 0.16 m over its near top edge
        ],
        dtype=np.float32,
    )
    camera /= np.linalg.norm(camera, axis=1, keepdims=True)
    origin = np.array([0.0, 0.0, 1.0])
    assert _kept_pixels(origin, 0.0, camera, box) == {0, 4}
    assert _kept_pixels(origin, 0.0, camera, box, reach=3.9) == set()  # beyond the reach
    assert _kept_pixels(origin, math.pi / 2, camera, box) == set()  # turned left: none
    assert _kept_pixels(origin, -math.pi / 2, camera, box) == {2}  # turned right: body +y
    # from inside the box every pixel may see it
    assert _kept_pixels(np.array([4.5, 0.0, 1.0]), 0.3, camera, box) == set(range(6))


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_culling_never_drops_a_pixel_that_sees_the_target(shape):
    """Random viewpoints around the target, every pixel cast by brute force, in the second room
    of a shared scene (shifted, as in the environment)."""
    camera, _ = camera_rays((96, 54), (87.0, 58.0))
    config = EnvConfig(target_shapes=(shape,))
    rng = np.random.default_rng(1)
    rooms = [sample_room(np.random.default_rng(seed), 4, config) for seed in (5, 6)]
    vertices, triangles, faces = side_by_side(rooms, 12.0)
    caster = RayCaster(vertices, triangles)
    room, shift = rooms[1], np.array([12.0, 0.0, 0.0])
    middle = room.target_box.mean(axis=0)
    seen = kept_total = 0
    for _ in range(12):
        position = np.clip(middle + rng.uniform((-3, -3, -1), (3, 3, 2)), 0.3, room.size - 0.3)
        bearing = np.arctan2(*(middle - position)[1::-1])
        yaw = bearing + rng.uniform(-0.7, 0.7)
        turned = rotate_xy(math.cos(yaw), math.sin(yaw), camera[:, 0], camera[:, 1])
        world = np.column_stack([*turned, camera[:, 2]])
        _, tri = caster.cast(position + shift, world, 10.0)
        on_target = np.flatnonzero((tri >= 0) & (faces[np.maximum(tri, 0)] >= 0))
        kept = _kept_pixels(position + shift, yaw, camera, room.target_box + shift)
        assert set(on_target.tolist()) <= kept
        seen += len(on_target)
        kept_total += len(kept)
    assert seen > 500  # the views do see the target
    assert kept_total < 0.8 * 12 * len(camera)  # and the culling prunes


def test_rooms_built_on_two_threads_give_the_same_rays_in_the_same_order():
    """Five rooms on two threads: more blocks than rooms, so some are empty (an empty block,
    finishing after the room's own block of the same start, once replaced its rays)."""
    rng = np.random.default_rng(4)
    camera, _ = camera_rays((24, 12), (87.0, 58.0))
    origin = rng.uniform(0.0, 4.0, (5, 3))
    low = rng.uniform(0.0, 3.0, (5, 3))
    box = np.stack([low, low + 1.0], axis=1)
    args = (origin, rng.uniform(-3, 3, 5), camera, lidar_rays((8, 2)), mapping_pixels((24, 12)))
    one = sensor_rays(*args, box, 10.0)
    two = sensor_rays(*args, box, 10.0, threads=2)
    assert len(np.unique(one[0])) == 5
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)
