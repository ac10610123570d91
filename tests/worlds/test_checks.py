import warnings

import pytest

from seminspect.worlds import WorldBuilder
from seminspect.worlds.checks import WorldWarning, warn_if_no_targets
from sim_worlds import box_world, car_world

VEHICLE_CLASSES = ("car", "truck")  # what a mission inspects by default


def test_a_world_without_targets_warns_in_one_line() -> None:
    world = box_world()  # one crate, no vehicle
    with pytest.warns(WorldWarning) as caught:
        warn_if_no_targets(world, ("car", "truck"))
    (warning,) = caught
    assert str(warning.message) == (
        "world 'box' has no targets (car, truck; it holds only crate): "
        "the mission will only explore"
    )


def test_an_empty_world_says_it_holds_no_objects() -> None:
    builder = WorldBuilder("empty")
    builder.add_ground((-5.0, -5.0), (5.0, 5.0))
    world = builder.build([(-5.0, -5.0, 0.0), (5.0, 5.0, 3.0)], (0.0, 0.0, 0.0))
    with pytest.warns(WorldWarning, match="it holds no objects"):
        warn_if_no_targets(world, VEHICLE_CLASSES)


def test_a_world_with_targets_is_silent() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_if_no_targets(car_world(), VEHICLE_CLASSES)
        warn_if_no_targets(box_world(), ("crate",))
