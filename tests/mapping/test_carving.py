"""Thinned free-space carving: levels, where rays start freeing, and the map it gives
against exact carving in a city street."""

import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.mapping.carving import (
    MAX_LEVEL,
    carve_from,
    index_levels,
    median_step,
    order_levels,
)
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.sensors import CameraModel, Lidar, render
from seminspect.worlds import generate_world

#: The share of exactly carved free cells that spacing-1 thinning may leave unknown.
MISSING_FREE_TOLERANCE = 0.02


def test_levels_count_trailing_zero_bits_up_to_the_top_level() -> None:
    index = np.array([1, 2, 3, 4, 6, 8, 12, -4, 0, 2**MAX_LEVEL, 2 ** (MAX_LEVEL + 3)])
    assert index_levels(index).tolist() == [0, 1, 0, 2, 1, 3, 2, 2] + [MAX_LEVEL] * 3


def test_levels_by_order_are_those_of_the_indices_and_read_only() -> None:
    levels = order_levels(100)
    np.testing.assert_array_equal(levels, index_levels(np.arange(100)))
    assert order_levels(100) is levels and not levels.flags.writeable


def test_rays_start_where_the_next_level_spreads_beyond_the_spacing() -> None:
    levels = np.array([0, 1, 2, MAX_LEVEL, 0])
    lengths = np.array([100.0, 100.0, 100.0, 100.0, 2.0])
    step, resolution, spacing = 0.01, 0.2, 1.0
    fractions = carve_from(levels, lengths, step, resolution, spacing)
    # level L starts at spacing * resolution / (2^(L+1) step): 10 m, 5 m, 2.5 m
    np.testing.assert_allclose(fractions[:3] * 100.0, [10.0, 5.0, 2.5])
    assert fractions[3] == 0.0  # the top level frees from the sensor
    assert fractions[4] == 1.0  # a ray shorter than its start only sets its end cell


@pytest.mark.parametrize("spacing", [0.0, -1.0, math.nan])
def test_a_spacing_that_is_not_positive_is_refused(spacing) -> None:
    with pytest.raises(InvalidInputError, match="spacing"):
        carve_from(np.zeros(2, dtype=np.int64), np.ones(2), 0.01, 0.2, spacing)


def test_the_median_step_along_lidar_rings_is_their_column_step() -> None:
    """Columns are the column step apart on the horizon ring, cos(elevation) of it above."""
    lidar = Lidar()
    directions, _ = lidar.rays
    rays = 20.0 * directions.astype(np.float64)
    step = median_step(rays, np.full(len(rays), 20.0))
    column = math.radians(lidar.horizontal_resolution_deg)
    assert column * math.cos(math.radians(lidar.max_elevation_deg)) < step < column
    assert median_step(rays[:1], np.ones(1)) == math.inf


@pytest.fixture(scope="module")
def street():
    world = generate_world("city", "small", seed=0)
    centre = world.bounds.mean(axis=0)
    poses = []
    for dx in np.linspace(-30.0, 30.0, 13):
        point = np.array([centre[0] + dx, centre[1], 0.7])
        if world.is_free(point[None], 0.4, "ground")[0]:
            poses.append((point, quat_from_yaw(float(dx) * 0.3)))
    assert len(poses) >= 3
    return world, poses[:4]


def _compare(exact: VoxelMap, thinned: VoxelMap) -> tuple[float, int]:
    assert np.array_equal(exact.states == OCCUPIED, thinned.states == OCCUPIED)
    free = exact.states == FREE
    missing = np.count_nonzero(free & (thinned.states != FREE)) / np.count_nonzero(free)
    extra = np.count_nonzero((thinned.states == FREE) & ~free)
    return missing, extra


@pytest.mark.parametrize("resolution", [0.2, 0.3])
def test_thinned_frames_and_scans_match_exact_carving_within_tolerance(street, resolution):
    world, poses = street
    camera, lidar = CameraModel(), Lidar()
    maps = {spacing: VoxelMap.covering(world, resolution) for spacing in (None, 1.0)}
    for position, orientation in poses:
        frame = render(world, camera, position, orientation)
        scan = lidar.scan(world, position, orientation)
        for spacing, grid in maps.items():
            grid.integrate_frame(frame, stride=4, carving_spacing=spacing)
            grid.integrate_scan(scan, clear_misses_to=30.0, carving_spacing=spacing)
    missing, extra = _compare(maps[None], maps[1.0])
    assert 0.0 < missing < MISSING_FREE_TOLERANCE
    assert extra <= 1e-4 * np.count_nonzero(maps[None].states == FREE)  # ties on cell borders
