import math

import numpy as np
import pytest
import shapely
from scipy import ndimage

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.worlds import generate_world
from seminspect.worlds.layout import Slot, footprint, place_vehicles

ROBOT_RADIUS = 0.4


def _check_clearances(world, gap: float) -> None:
    vehicles = world.instances_of("car", "truck")
    obstacles = [i.footprint for i in world.instances_of("building")]
    for k, a in enumerate(vehicles):
        for b in vehicles[k + 1 :]:
            assert a.footprint.distance(b.footprint) >= gap - 0.05
            assert np.linalg.norm(a.centroid[:2] - b.centroid[:2]) > 8.0
        for obstacle in obstacles:
            assert a.footprint.distance(obstacle) >= gap - 0.05


def _check_rings_reachable(world, view_distance: float) -> None:
    """A 0.4 m robot can drive a ring at ``view_distance`` around every vehicle, from the start."""
    grid = world.collision.ground
    free = grid.distance - grid.slack >= ROBOT_RADIUS
    regions, _ = ndimage.label(free)

    def region(points):
        idx = np.floor((np.asarray(points) - grid.origin[:2]) / grid.resolution).astype(int)
        return regions[idx[:, 0], idx[:, 1]]

    home = region([world.start_position[:2]])[0]
    assert home > 0
    for vehicle in world.instances_of("car", "truck"):
        ring = vehicle.footprint.buffer(view_distance).exterior
        points = [ring.interpolate(d).coords[0] for d in np.arange(0.0, ring.length, 0.5)]
        assert np.all(region(points) == home), vehicle.name


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_city_vehicles_keep_their_gaps_and_can_be_circled(seed) -> None:
    world = generate_world("city", "large", seed=seed)
    _check_clearances(world, 7.0)
    _check_rings_reachable(world, 2.5)
    inside = shapely.box(*world.bounds[0, :2], *world.bounds[1, :2])
    assert all(inside.contains(v.footprint) for v in world.instances_of("car", "truck"))


def test_campus_cars_can_be_circled() -> None:
    world = generate_world("campus", "large", seed=5)
    _check_clearances(world, 6.5)
    _check_rings_reachable(world, 2.5)


def test_footprint_is_a_turned_rectangle() -> None:
    shape = footprint(1.0, 2.0, math.pi / 2, 4.0, 2.0)
    assert shape.area == pytest.approx(8.0)
    assert shape.bounds == pytest.approx((0.0, 0.0, 2.0, 4.0))


def test_too_many_vehicles_is_a_clear_error() -> None:
    slots = [Slot(float(x), 0.0, 0.0) for x in range(0, 30, 5)]
    with pytest.raises(InvalidInputError, match="of 4 vehicles fit"):
        place_vehicles(
            make_rng(0, "t"),
            slots,
            4,
            truck_share=0.0,
            obstacles=shapely.GeometryCollection(),
            keep_clear=shapely.GeometryCollection(),
        )
