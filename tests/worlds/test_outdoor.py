"""The outdoor world of 001 Sec IV: terrain patches, trees, cars and a drivable path."""

import numpy as np
import pytest
import shapely

from seminspect.core.errors import InvalidInputError
from seminspect.worlds import generate_world
from seminspect.worlds.outdoor import (
    SCENARIOS,
    TERRAIN_CLASSES,
    TREE_MARGIN,
    drive_path,
    terrain_patches,
)


@pytest.fixture(scope="module", params=sorted(SCENARIOS))
def world(request):
    return generate_world("outdoor", request.param, seed=5)


def test_patches_tile_the_ground_without_overlap(world) -> None:
    patches = terrain_patches(world)
    assert {cls for cls, _ in patches} == set(TERRAIN_CLASSES)
    ground = shapely.box(*world.bounds[0, :2], *world.bounds[1, :2])
    assert sum(p.area for _, p in patches) == pytest.approx(ground.area)
    assert shapely.union_all([p for _, p in patches]).equals(ground)


def test_ground_faces_carry_the_class_of_their_patch(world) -> None:
    patches = terrain_patches(world)
    objects = shapely.union_all([i.footprint for i in world.instances.values()]).buffer(0.5)
    rng = np.random.default_rng(0)
    xy = rng.uniform(world.bounds[0, :2], world.bounds[1, :2], (400, 2))
    xy = xy[~shapely.contains_xy(objects, xy[:, 0], xy[:, 1])]
    origins = np.column_stack([xy, np.full(len(xy), 0.5)])
    _, faces = world.raycaster.cast(origins, np.tile([0.0, 0.0, -1.0], (len(xy), 1)), 1.0)
    assert np.all(faces >= 0) and np.all(world.face_instance[faces] == 0)
    seen = [world.class_names[c] for c in world.face_class[faces]]
    for (x, y), cls in zip(xy, seen, strict=True):
        assert cls == next(c for c, p in patches if p.covers(shapely.Point(x, y)))


def test_cars_park_on_asphalt_and_trees_stand_on_grass(world) -> None:
    layout = SCENARIOS[world.metadata["scenario"]]
    patches = terrain_patches(world)
    asphalt = shapely.union_all([p for c, p in patches if c == "asphalt"])
    grass = shapely.union_all([p for c, p in patches if c == "grass"])
    cars, trees = world.instances_of("car"), world.instances_of("tree")
    assert (len(cars), len(trees)) == (layout.cars, layout.trees)
    assert all(asphalt.contains(car.footprint) for car in cars)
    assert all(car.parts and car.height > 1.3 for car in cars)
    path = shapely.LineString(drive_path(world))
    for tree in trees:
        assert tree.parts == ["crown", "trunk"] and 4.0 < tree.height < 8.0
        trunk = shapely.Point(tree.centroid[:2])
        assert grass.buffer(-TREE_MARGIN + 0.01).contains(trunk)
        assert trunk.distance(path) >= TREE_MARGIN


def test_a_ground_robot_can_drive_the_whole_path(world) -> None:
    waypoints = drive_path(world)
    np.testing.assert_allclose(waypoints[0], world.start_position[:2])
    line = shapely.LineString(waypoints)
    samples = [line.interpolate(d).coords[0] for d in np.arange(0.0, line.length, 0.5)]
    points = np.column_stack([samples, np.full(len(samples), 0.8)])
    assert world.is_free(points, 0.4, "ground").all()


def test_seed_moves_objects_but_not_the_layout() -> None:
    a, b = generate_world("outdoor", "small", seed=0), generate_world("outdoor", "small", seed=1)
    assert a.metadata["terrain_patches"] == b.metadata["terrain_patches"]
    centres = [{tuple(np.round(i.centroid, 3)) for i in w.instances.values()} for w in (a, b)]
    assert centres[0] != centres[1]


def test_worlds_without_paths_or_patches_are_refused() -> None:
    city = generate_world("city", "small")
    with pytest.raises(InvalidInputError, match="no drive path"):
        drive_path(city)
    with pytest.raises(InvalidInputError, match="no terrain patches"):
        terrain_patches(city)
    city.metadata["drive_path"] = [[0.0, 0.0]]
    with pytest.raises(InvalidInputError, match=">= 2"):
        drive_path(city)
    city.metadata["drive_path"] = [[0.0, "x"], [1.0, 1.0]]
    with pytest.raises(InvalidInputError, match="malformed"):
        drive_path(city)
