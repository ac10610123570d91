import math

import numpy as np
import pytest

from seminspect.core.cache import CACHE_ENV
from seminspect.core.errors import InvalidInputError
from sim_worlds import box_world

BOX_LO, BOX_HI = np.array([4.0, -1.0, 0.0]), np.array([6.0, 1.0, 2.0])


def _distance_to_box(points: np.ndarray) -> np.ndarray:
    outside = np.maximum(np.maximum(BOX_LO - points, points - BOX_HI), 0.0)
    return np.linalg.norm(outside, axis=1)


@pytest.fixture(scope="module")
def world():
    return box_world(lower=BOX_LO, upper=BOX_HI, floating=((-4.0, -1.0, 3.0), (-3.0, 1.0, 3.5)))


def test_aerial_clearance_is_a_tight_lower_bound(world) -> None:
    rng = np.random.default_rng(1)
    points = rng.uniform([0.0, -4.0, 0.5], [9.0, 4.0, 2.5], size=(400, 3))
    truth = np.minimum(_distance_to_box(points), points[:, 2])  # box or ground
    estimate = world.clearance(points, "aerial")
    slack = world.collision.aerial.slack
    assert np.all(estimate <= truth + 1e-9)
    assert np.all(estimate >= truth - 2 * slack - 1e-9)
    assert np.mean(truth - estimate) < 1.5 * slack


def test_ground_clearance_ignores_the_ground_and_things_overhead(world) -> None:
    rng = np.random.default_rng(2)
    points = rng.uniform([0.0, -4.0, 0.7], [9.0, 4.0, 0.7], size=(300, 3))
    flat = points.copy()
    flat[:, 2] = 1.0  # horizontal distance to the box
    truth = _distance_to_box(flat)
    estimate = world.clearance(points, "ground")
    assert np.all(estimate <= truth + 1e-9)
    assert np.all(estimate >= truth - 2 * world.collision.ground.slack - 1e-9)
    inside = world.clearance([(5.0, 0.0, 0.7), (5.0, 0.0, 1.0)], "ground")
    assert inside.tolist() == [0.0, 0.0]  # the crate is solid, not just its surface
    # the sign floating at 3 m blocks a drone, not a legged robot walking under it
    under_sign = [(-3.5, 0.0, 0.7)]
    assert world.is_free(under_sign, 0.4, "ground")[0]
    assert not world.is_free([(-3.5, 0.0, 3.25)], 0.4, "aerial")[0]


def test_outside_the_world_is_never_free(world) -> None:
    outside = [(50.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.0, 0.0, 9.0)]
    assert world.clearance(outside, "aerial").tolist() == [0.0, 0.0, 0.0]
    assert not world.is_free([(50.0, 0.0, 0.7)], 0.1, "ground")[0]


def test_segments_through_and_beside_an_obstacle(world) -> None:
    assert not world.segment_is_free((0.0, 0.0, 0.7), (9.0, 0.0, 0.7), 0.4, "ground")
    assert world.segment_is_free((0.0, 3.0, 0.7), (9.0, 3.0, 0.7), 0.4, "ground")
    sweep = world.collision.sweep((0.0, 0.0, 0.7), (9.0, 0.0, 0.7), 0.4, "ground")
    stop = 9.0 * sweep.free_until
    contact = 9.0 * sweep.contact
    assert stop < contact and 4.0 - 0.4 - 0.2 <= stop <= 4.0 - 0.4
    assert contact - stop <= world.collision.ground.resolution


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda w: w.clearance([(0, 0, 1)], "swimming"), "collision mode"),
        (lambda w: w.is_free([(0, 0, 1)], -1.0), "radius"),
        (lambda w: w.is_free([(0, 0, math.nan)], 1.0), "NaN"),
        (lambda w: w.segment_is_free((0, 0), (1, 1, 1), 0.1), "3 coordinates"),
    ],
)
def test_bad_queries_are_refused(world, call, message) -> None:
    with pytest.raises(InvalidInputError, match=message):
        call(world)


@pytest.mark.parametrize("mode", ["ground", "aerial"])
def test_a_cached_grid_equals_a_fresh_one(mode, tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, "off")
    fresh = box_world().collision.grid(mode)
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    stored = box_world().collision.grid(mode)  # builds and stores
    assert len(list((tmp_path / "collision").iterdir())) == 1
    read = box_world().collision.grid(mode)  # reads back
    for grid in (stored, read):
        assert grid.resolution == fresh.resolution
        np.testing.assert_array_equal(grid.origin, fresh.origin)
        assert grid.distance.dtype == fresh.distance.dtype
        np.testing.assert_array_equal(grid.distance, fresh.distance)


def test_a_changed_world_misses_the_cache(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    box_world().collision.grid("ground")
    taller = box_world(upper=(6.0, 1.0, 2.5)).collision.grid("ground")  # another mesh
    assert len(list((tmp_path / "collision").iterdir())) == 2
    monkeypatch.setenv(CACHE_ENV, "off")
    np.testing.assert_array_equal(
        taller.distance, box_world(upper=(6.0, 1.0, 2.5)).collision.grid("ground").distance
    )
