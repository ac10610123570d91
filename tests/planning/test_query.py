import pytest

from seminspect.core.errors import InvalidInputError, PlanningError, UnknownNameError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.perception.observation import Observation
from seminspect.planning.query import Query, Verb, normalise_name, parse_query, resolve_query


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("Visit hood-1 in Level-0 of car-1", Query(Verb.VISIT, "car-1", "level-0", "hood-1")),
        (
            "observe  Wheel-1 in level 0 of CAR-1",
            Query(Verb.OBSERVE, "car-1", "level-0", "wheel-1"),
        ),
        ("Visit car-1", Query(Verb.VISIT, "car-1")),
        ("car-1", Query(Verb.VISIT, "car-1")),
        ("Visit Level-1 of truck-16", Query(Verb.VISIT, "truck-16", "level-1")),
        ("Visit hood-1 of car-1.", Query(Verb.VISIT, "car-1", None, "hood-1")),
        (
            "go to front left light 2 at Level-0 of car-1",
            Query(Verb.VISIT, "car-1", "level-0", "front-left-light-2"),
        ),
        ("Navigate to pose-3 in Level-0 of car-1", Query(Verb.VISIT, "car-1", "level-0", "pose-3")),
    ],
)
def test_the_papers_query_forms_parse(text: str, expected: Query) -> None:
    assert parse_query(text) == expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty query"),
        ("Visit", "names no node"),
        ("Visit Level-0", "must end with a target"),
        ("Visit hood-1 in car-1 of Level-0", "must end with a target"),
        ("Visit hood-1 in pose-3 of car-1", "not a level name"),
        ("Visit a in b in c in d", "at most"),
        ("Visit h@od in Level-0 of car-1", "not a node name"),
        ("fly to car-1", "unknown verb"),
        ("Visit " + "x" * 400, "longer than"),
    ],
)
def test_malformed_queries_are_refused(text: str, message: str) -> None:
    with pytest.raises(InvalidInputError, match=message):
        parse_query(text)


def test_names_are_normalised() -> None:
    assert normalise_name("  Front Left   Light 2 ") == "front-left-light-2"
    assert normalise_name("LEVEL--0") == "level-0"
    assert (
        str(parse_query("observe hood-1 in level 0 of car-1"))
        == "Observe hood-1 in level-0 of car-1"
    )


@pytest.fixture(scope="module")
def graph():
    graph = synthetic_graph(3, poses_per_level=6, levels=2, parts_per_pose=3, seed=5)
    graph.register_target(Observation([400, 400, 0], label="truck", score=1, mask_area=1))
    graph.optimise_targets()
    return graph


def test_resolution_finds_every_layer(graph) -> None:
    first = graph.targets()[0].id
    feature = graph.target(first).levels[1].poses[2].features[0]
    text = f"Visit {feature.name} in Level-1 of {first}"
    assert resolve_query(graph, parse_query(text)) == feature.id
    level = resolve_query(graph, parse_query(f"Visit Level-1 of {first.upper()}"))
    assert level == f"{first}/Level-1"
    pose = resolve_query(graph, parse_query(f"Visit pose-2 in Level-0 of {first}"))
    assert pose == f"{first}/Level-0/pose-2"
    assert resolve_query(graph, parse_query(f"Visit {first}")) == first


def test_unknown_names_list_the_closest(graph) -> None:
    first = graph.targets()[0].id
    with pytest.raises(
        UnknownNameError, match=f"unknown target '{first}7'; did you mean '{first}'"
    ):
        resolve_query(graph, parse_query(f"Visit {first}7"))
    with pytest.raises(UnknownNameError, match=f"unknown level 'level-5' of {first}; did you mean"):
        resolve_query(graph, parse_query(f"Visit Level-5 of {first}"))
    name = graph.target(first).levels[0].poses[0].features[0].name
    typo = name[:-3] + name[-2:]  # drop a letter
    with pytest.raises(UnknownNameError, match=f"in Level-0 of {first}; did you mean '{name}'"):
        resolve_query(graph, parse_query(f"Visit {typo} in Level-0 of {first}"))


def test_ambiguous_and_uninspected_names(graph) -> None:
    first = graph.targets()[0]
    level0 = {f.name for p in first.levels[0].poses for f in p.features}
    level1 = {f.name for p in first.levels[1].poses for f in p.features}
    shared = sorted(level0 & level1)[0]
    with pytest.raises(InvalidInputError, match=r"ambiguous.*name the level"):
        resolve_query(graph, parse_query(f"Visit {shared} of {first.id}"))
    with pytest.raises(PlanningError, match="not been inspected"):
        resolve_query(graph, parse_query("Visit hood-1 of truck-3"))


def test_a_sites_own_part_names_resolve() -> None:
    """Feature names come from the world's parts (any valid label, not only the built-in
    vocabulary): spaces, underscores and capitals are written as the graph names them."""
    graph = LayeredSemanticGraph()
    graph.register_target(Observation([0, 0, 0.7], label="car", score=1, mask_area=1))
    graph.optimise_targets()
    (car,) = graph.targets()
    graph.begin_inspection(car.id, Observation.view_pose([-3, 0, 0.7]))
    graph.register_pose(Observation.view_pose([-3, 1, 0.7]))
    for label, offset in (("Rear Window", 0.0), ("seat_belt", 0.5), ("interior", 1.0)):
        graph.register_feature(
            Observation([-1, offset, 1.0], label=label, score=0.9, mask_area=900)
        )
    graph.finish_inspection()
    names = {f.name: f.id for p in graph.target(car.id).levels[0].poses for f in p.features}
    assert set(names) == {"rear-window-1", "seat_belt-1", "interior-1"}
    for text, name in (
        (f"Visit rear window 1 in Level-0 of {car.id}", "rear-window-1"),
        (f"Observe Seat_Belt-1 of {car.id}", "seat_belt-1"),
        (f"Visit interior-1 of {car.id}", "interior-1"),
    ):
        assert resolve_query(graph, parse_query(text)) == names[name]
