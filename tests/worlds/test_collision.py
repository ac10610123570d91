import math
import zipfile

import numpy as np
import pytest

from seminspect.core.cache import CACHE_ENV, CacheWarning
from seminspect.core.errors import InvalidInputError
from seminspect.worlds.collision import CollisionField, check_grid_sizes
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


def _flip_values(path) -> None:
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 64] = bytes(b ^ 0x5A for b in data[middle : middle + 64])
    path.write_bytes(bytes(data))


def _zip_in_place(path) -> None:
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("arr_0.npy", b"not the grid")


DAMAGES = {
    "flipped bytes": _flip_values,
    "empty": lambda path: path.write_bytes(b""),
    "zip": _zip_in_place,
    "wrong shape": lambda path: np.save(path, np.ones((10, 10), dtype=np.float32)),
}


@pytest.mark.parametrize("damage", DAMAGES.values(), ids=DAMAGES.keys())
@pytest.mark.parametrize("mode", ["ground", "aerial"])
def test_a_damaged_cached_grid_is_rebuilt_as_a_clean_build(mode, damage, tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, "off")
    fresh = box_world().collision.grid(mode)
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    box_world().collision.grid(mode)  # builds and stores
    (stored,) = (tmp_path / "collision").iterdir()
    damage(stored)
    with pytest.warns(CacheWarning, match="damaged cache entry"):
        rebuilt = box_world().collision.grid(mode)
    again = box_world().collision.grid(mode)  # the replacement reads back sound
    for grid in (rebuilt, again):
        assert grid.distance.dtype == fresh.distance.dtype
        np.testing.assert_array_equal(grid.distance, fresh.distance)


def test_a_world_too_large_for_its_grids_is_refused_before_allocating() -> None:
    bounds = np.array([[0.0, 0.0, 0.0], [2e6, 2e6, 10.0]])
    triangles = np.zeros((1, 3, 3))
    with pytest.raises(InvalidInputError, match=r"ground collision grid would have 1\.6e\+15"):
        CollisionField(triangles, np.zeros(1, np.int32), np.zeros(1, bool), bounds, ground_z=0.0)
    with pytest.raises(InvalidInputError, match=r"aerial collision grid .* at 1 m"):
        check_grid_sizes(np.array([[0.0, 0.0, 0.0], [1e4, 1e4, 10.0]]), ground_resolution=10.0)
    with pytest.raises(InvalidInputError, match="not finite"):
        check_grid_sizes(np.array([[0.0, 0.0, 0.0], [np.inf, 1.0, 1.0]]))


def test_every_built_in_world_fits_the_grid_bound_by_far() -> None:
    city = np.array([[0.0, 0.0, 0.0], [150.0, 100.0, 5.0]])  # the largest built-in world
    check_grid_sizes(city * 5.0)  # 750 x 500 m: 150 M ground cells, under the bound
    with pytest.raises(InvalidInputError):
        check_grid_sizes(city * 6.0)
