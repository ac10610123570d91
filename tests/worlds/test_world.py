import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.worlds import World, WorldBuilder
from sim_worlds import box_world


def test_instances_carry_their_ground_truth() -> None:
    world = box_world(lower=(4, -1, 0), upper=(6, 1, 2))
    crate = world.instance_named("crate-1")
    assert crate.class_name == "crate" and crate.parts == ["lid", "side"]
    assert crate.volume == pytest.approx(8.0)
    assert crate.footprint.area == pytest.approx(4.0)
    assert crate.height == pytest.approx(2.0)
    np.testing.assert_allclose(crate.bbox_min, [4, -1, 0])
    np.testing.assert_allclose(crate.centroid, [5, 0, 1], atol=1e-9)
    assert [i.name for i in world.instances_of("crate")] == ["crate-1"]
    assert world.instances_of("car") == []
    assert world.class_names[:2] == ["background", "ground"] and world.part_names[0] == ""


def test_unknown_names_suggest_close_ones() -> None:
    world = box_world()
    with pytest.raises(UnknownNameError, match="crate-1"):
        world.instance_named("crate-11")
    with pytest.raises(UnknownNameError, match="lid"):
        world.part_id("lids")
    assert world.class_names[world.class_id("crate")] == "crate"


def test_open_surfaces_fall_back_to_the_hull_volume() -> None:
    builder = WorldBuilder("open")
    builder.add_ground((-5, -5), (5, 5))
    sheet = builder.new_instance("sign")
    # a unit cube without its top face: not closed
    cube = np.array(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
    )
    sides = [(0, 2, 1), (0, 3, 2), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6)]
    builder.add_faces(cube, [*sides, (3, 0, 4), (3, 4, 7)], "sign", "panel", sheet)
    world = builder.build([(-5, -5, 0), (5, 5, 2)], (-4, -4, 0))
    assert world.instances[sheet].volume == pytest.approx(1.0)


def test_inconsistent_worlds_are_refused() -> None:
    world = box_world()
    fields = {
        "name": "bad",
        "mesh": world.mesh,
        "face_instance": world.face_instance,
        "face_class": world.face_class,
        "face_part": world.face_part,
        "class_names": world.class_names,
        "part_names": world.part_names,
        "instances": world.instances,
        "bounds": world.bounds,
        "start_position": world.start_position,
    }
    World(**fields)  # the original fields are fine
    for change in (
        {"face_instance": world.face_instance[:-1]},
        {"part_names": ["x", *world.part_names[1:]]},
        {"class_names": world.class_names[:1]},
        {"bounds": np.zeros((2, 3))},
        {"start_position": [np.nan, 0, 0]},
    ):
        with pytest.raises(InvalidInputError):
            World(**(fields | change))


def test_builder_refuses_mislabelled_faces() -> None:
    builder = WorldBuilder("w")
    car = builder.new_instance("car")
    with pytest.raises(InvalidInputError, match="not a 'truck'"):
        builder.add_faces(np.eye(3), [(0, 1, 2)], "truck", instance=car)
    with pytest.raises(InvalidInputError, match="reserved"):
        builder.new_instance("ground")
    with pytest.raises(InvalidInputError, match="2 part labels for 1 faces"):
        builder.add_faces(np.eye(3), [(0, 1, 2)], "wall", ["a", "b"])
    with pytest.raises(InvalidInputError, match="two objects"):
        builder.new_instance("car", "car-1")
    with pytest.raises(InvalidInputError, match="no geometry"):
        WorldBuilder("empty").build([(0, 0, 0), (1, 1, 1)], (0, 0, 0))
