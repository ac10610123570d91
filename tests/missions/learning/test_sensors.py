"""The 004 sensors: unit body-frame rays, the focus area, the mapping pixels and range noise."""

import numpy as np

from seminspect.missions.learning.sensors import (
    camera_rays,
    focus_mask,
    lidar_rays,
    mapping_pixels,
    noisy_ranges,
)


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
