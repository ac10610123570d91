"""The collapsed buildings, underground sites and rooms hold what their papers describe."""

import numpy as np
import pytest
import shapely

from seminspect.worlds import generate_world, mine_drift_pair
from seminspect.worlds.collapsed import RUBBLE_REACH, SCENARIOS, STOREY


@pytest.mark.parametrize("scenario", ["fire-station", "industrial"])
def test_collapsed_buildings_have_features_levels_and_a_free_ring(scenario) -> None:
    world = generate_world("collapsed-buildings", scenario)
    main, annex = world.instances_of("building")
    assert {"window", "person", "rubble", "wall", "roof"} <= set(main.parts)
    assert {"window", "wall"} <= set(annex.parts)
    assert main.height >= 2 * STOREY - 0.1 and annex.height >= 2 * STOREY - 0.1
    spec = SCENARIOS[scenario][0]
    walls = shapely.box(*spec.origin, spec.origin[0] + spec.length, spec.origin[1] + spec.width)
    # rubble and casualties stay near the walls, so a ring 1.5 m beyond them is drivable
    assert main.footprint.buffer(-0.01).within(walls.buffer(RUBBLE_REACH))
    ring = walls.buffer(RUBBLE_REACH + 1.5).exterior
    points = [(*ring.interpolate(d).coords[0], 0.7) for d in np.arange(0, ring.length, 1.0)]
    assert world.is_free(points, 0.4, "ground").all()


@pytest.mark.parametrize(("scenario", "storeys"), [("fire-station", 2), ("industrial", 5)])
def test_main_building_is_as_tall_as_its_storeys_under_open_airspace(scenario, storeys) -> None:
    """000 Table 3's 4 and 10 levels need a 7 m and a 17.5 m building (1.66 m level steps)."""
    world = generate_world("collapsed-buildings", scenario)
    main, annex = world.instances_of("building")
    assert main.bbox_max[2] == pytest.approx(storeys * STOREY, abs=0.01)
    assert annex.bbox_max[2] == pytest.approx(2 * STOREY, abs=0.01)
    ceiling = world.bounds[1][2]
    assert ceiling - main.bbox_max[2] >= 4.0  # a flying robot clears the roof by its margin
    top = (*main.centroid[:2], main.bbox_max[2] + 2.0)
    assert world.is_free([top], 0.4, "aerial")[0]


def test_small_collapsed_site_holds_one_collapsed_building_with_every_feature() -> None:
    world = generate_world("collapsed-buildings", "small")
    (building,) = world.instances_of("building")
    assert {"window", "person", "rubble", "wall", "roof"} <= set(building.parts)
    assert building.height >= 2 * STOREY - 0.1
    low, high = world.bounds
    assert (building.bbox_min[:2] > low[:2] + 8.0).all()  # room to fly around it
    assert (building.bbox_max[:2] < high[:2] - 8.0).all()
    assert (high - low)[0] < generate_world("collapsed-buildings", "fire-station").bounds[1][0]


def test_subterranean_is_the_papers_tunnel_with_one_car() -> None:
    world = generate_world("subterranean")
    np.testing.assert_allclose(world.bounds[1] - world.bounds[0], [10, 6, 4])
    (car,) = world.instances_of("car")
    assert abs(car.centroid[0] - 5.0) < 0.2 and abs(car.centroid[1] - 3.0) < 0.1
    # a robot fits between the car and the rough walls
    side = car.bbox_max[1] + 0.8
    assert world.is_free([(5.0, side, 0.7)], 0.4, "ground")[0]


def test_current_mine_drift_differs_from_the_historical_one() -> None:
    historical, current = mine_drift_pair(seed=2, recession=1.2)
    assert not historical.instances_of("rock") and len(current.instances_of("rock")) == 1
    np.testing.assert_array_equal(historical.bounds, current.bounds)
    old = historical.instance_named("rock-face-1")
    new = current.instance_named("rock-face-1")
    # same rock everywhere but at the face, which has receded by up to the recession
    assert new.bbox_max[0] - old.bbox_max[0] > 0.8
    old_face = historical.triangles[historical.face_instance == old.id]
    new_face = current.triangles[current.face_instance == new.id]
    pushed = new_face[..., 0] - old_face[..., 0]
    assert pushed.min() >= -1e-9 and pushed.max() <= 1.2 + 1e-9
    np.testing.assert_array_equal(new_face[..., 1:], old_face[..., 1:])
    walls = historical.face_class == historical.class_id("wall")
    np.testing.assert_array_equal(
        historical.triangles[walls],
        current.triangles[current.face_class == current.class_id("wall")],
    )
    no_boulder = generate_world("mine-drift", "current", seed=2, obstacle=False)
    assert not no_boulder.instances_of("rock")


def test_rooms_follow_004_dimensions() -> None:
    for seed in range(5):
        world = generate_world("room", "4", seed=seed)
        extent = world.bounds[1] - world.bounds[0]
        assert 4 <= extent[0] <= 20 and 4 <= extent[1] <= 20 and 2 <= extent[2] <= 8
        (target,) = world.instances_of("target")
        assert np.sum(world.face_instance == target.id) == 60
