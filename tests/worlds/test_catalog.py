import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.worlds import available_worlds, generate_world

CASES = [(spec.name, scenario) for spec in available_worlds() for scenario in spec.scenarios]


def test_the_catalogue_lists_every_world() -> None:
    names = {spec.name for spec in available_worlds()}
    assert names == {
        "city",
        "collapsed-buildings",
        "campus",
        "subterranean",
        "mine-drift",
        "room",
        "outdoor",
    }
    for spec in available_worlds():
        assert spec.default_scenario in spec.scenarios and spec.description


@pytest.mark.parametrize(("name", "scenario"), CASES)
def test_every_world_is_deterministic_and_labelled(name, scenario) -> None:
    first = generate_world(name, scenario, seed=3)
    again = generate_world(name, scenario, seed=3)
    np.testing.assert_array_equal(first.mesh.vertices, again.mesh.vertices)
    np.testing.assert_array_equal(first.face_part, again.face_part)
    assert first.metadata["scenario"] == scenario and first.metadata["generator"] == name
    assert first.instances, "every world holds at least one object"
    assert len(first.face_instance) == len(first.mesh.faces)
    assert np.all(first.bounds[0] <= first.start_position) and np.all(
        first.start_position <= first.bounds[1]
    )
    lifted = first.start_position + np.array([0.0, 0.0, 0.7])
    assert first.is_free([lifted], 0.4, "ground")[0]


@pytest.mark.parametrize(
    "name", ["city", "collapsed-buildings", "campus", "mine-drift", "room", "outdoor"]
)
def test_seeds_change_the_world(name) -> None:
    a, b = generate_world(name, seed=0), generate_world(name, seed=1)
    assert a.mesh.vertices.shape != b.mesh.vertices.shape or not np.array_equal(
        a.mesh.vertices, b.mesh.vertices
    )


def test_city_scenarios_hold_5_10_20_nested_vehicles() -> None:
    centres = {}
    for scenario, count in (("small", 5), ("medium", 10), ("large", 20)):
        world = generate_world("city", scenario, seed=4)
        vehicles = world.instances_of("car", "truck")
        assert len(vehicles) == count
        centres[scenario] = {tuple(np.round(v.centroid, 6)) for v in vehicles}
    assert centres["small"] <= centres["medium"] <= centres["large"]
    vehicles = generate_world("city", "large").instances_of("car", "truck")
    assert {v.class_name for v in vehicles} == {"car", "truck"}


def test_campus_and_rooms_follow_the_paper_counts() -> None:
    for scenario, count in (("small", 3), ("medium", 5), ("large", 7)):
        assert len(generate_world("campus", scenario).instances_of("car")) == count
    for count in (0, 4, 9, 14, 19):
        assert len(generate_world("room", str(count)).instances_of("obstacle")) == count


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: generate_world("citty"), UnknownNameError, "did you mean 'city'"),
        (lambda: generate_world("city", "huge"), UnknownNameError, "city scenario 'huge'"),
        (lambda: generate_world("city", seed=-1), InvalidInputError, "seed"),
        (lambda: generate_world("room", colour="red"), InvalidInputError, "no option"),
        (lambda: generate_world("mine-drift", length=5.0), InvalidInputError, "10-200"),
        (lambda: generate_world("city", truck_share=1.5), InvalidInputError, "truck_share"),
    ],
)
def test_bad_requests_raise_clear_errors(call, error, message) -> None:
    with pytest.raises(error, match=message):
        call()
