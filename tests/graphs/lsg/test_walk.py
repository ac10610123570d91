"""Walking a 3DLSG from Python: down and back up the layers, and one-line reprs."""

from __future__ import annotations

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg import (
    Edge,
    EdgeKind,
    Layer,
    LayeredSemanticGraph,
    LevelNode,
    TargetStatus,
    example_graph_path,
    load_graph,
    synthetic_graph,
)
from seminspect.perception.observation import Observation

REPR_LIMIT = 200  # characters: a repr is a line, not a dump


@pytest.fixture(scope="module")
def example() -> LayeredSemanticGraph:
    return load_graph(example_graph_path())


def inspected_by_operators() -> LayeredSemanticGraph:
    """One car inspected through the registration operators (not the file loader)."""
    graph = LayeredSemanticGraph(robot_position=[0, 0, 0.7])
    graph.register_target(Observation([9.0, 0.0, 0.7], label="car", score=0.9, mask_area=5000))
    graph.register_target(Observation([0.0, 20.0, 0.7], label="truck", score=0.8, mask_area=90))
    graph.optimise_targets()
    graph.begin_inspection("car-0", Observation.view_pose([7.0, 0.0, 0.7]))
    for i, (x, y) in enumerate([(10, -3), (13, 0), (10, 3), (7, 0)]):
        view = Observation.view_pose([x, y, 0.7], quat_from_yaw(0.5), image=f"{i}.png")
        graph.register_pose(view)
        graph.register_feature(Observation([11.8, 0, 0.8], label="hood", score=0.7, mask_area=9))
    graph.finish_inspection()
    return graph


def test_every_node_leads_back_up_to_the_node_that_holds_it(example) -> None:
    for target in example.targets():
        assert target.parent is example.robot and target.name == target.id
        for level in target.levels:
            assert level.target is target and level.target_id == target.id
            for pose in level.poses:
                assert pose.level is level and pose.level_id == level.id
                for feature in pose.features:
                    assert feature.pose is pose and feature.pose_id == pose.id
                    assert feature.level is level and feature.id.startswith(level.id + "/")


def test_the_layer_walkers_list_every_node_of_their_layer_in_order(example) -> None:
    stats = example.population()
    levels, poses, features = example.levels(), example.poses(), example.features()
    # a layer's local graphs each hold one parent borrowed from the layer above
    assert len(levels) == stats.level.nodes - len(example.local_graphs(Layer.LEVEL)) == 10
    assert len(poses) == stats.pose.nodes - len(levels) == 120
    assert len(features) == stats.feature.nodes - len(example.local_graphs(Layer.FEATURE))
    assert levels == [lv for t in example.targets() for lv in t.levels]
    assert poses == [p for lv in levels for p in lv.poses]
    assert [f.id for f in features] == [f.id for p in poses for f in p.features]
    walked = [example.robot, *example.targets(), *levels, *poses, *features]
    assert {n.id for n in walked} == {n.id for n in example.nodes()}


def test_the_registration_operators_set_the_way_up_too() -> None:
    graph = inspected_by_operators()
    car, truck = graph.targets(TargetStatus.INSPECTED)[0], graph.target("TRUCK-1")
    assert truck.parent is graph.robot and truck.levels == []
    (hood,) = graph.features()
    assert hood.level.target is car and hood.pose in car.levels[0].poses
    assert graph.poses()[0].yaw == pytest.approx(0.5)


def test_a_node_never_inserted_says_it_has_no_parent() -> None:
    level = LevelNode("car-0/Level-0", "Level-0", 0, "car-0", np.zeros(3), 0.0)
    with pytest.raises(InvalidInputError, match="car-0/Level-0 is not in a graph, so it has no"):
        _ = level.target


def test_reprs_are_one_short_informative_line(example) -> None:
    car = example.target("car-1")
    level = car.levels[0]
    pose = level.poses[1]
    feature = pose.features[0]
    expected = {
        car: ("TargetNode('car-1'", "label='car'", "status='inspected'", "levels=2"),
        level: ("LevelNode('car-1/Level-0'", "poses=12", "position=(42.66, 13.68, 0.70)"),
        pose: ("PoseNode('car-1/Level-0/pose-1'", "features=2", "image='car-1/L0/001.png'"),
        feature: ("FeatureNode('car-1/Level-0/back-right-door-1'", "label='back-right-door'"),
        example.robot: ("RobotNode(position=(0.00, 0.00, 0.00)",),
        car.level_graph: ("LocalGraph(layer='level', parent='car-1', nodes=3, edges=3)",),
        example.edge(car.id, "robot"): ("Edge('car-1', 'robot', kind='symbolic'",),
    }
    for node, parts in expected.items():
        text = repr(node)
        assert "\n" not in text and len(text) < REPR_LIMIT, text
        for part in parts:
            assert part in text, (part, text)


def test_the_graph_repr_counts_each_layer(example) -> None:
    assert repr(example) == (
        "LayeredSemanticGraph(targets=5, inspected=5, levels=10, poses=120, features=200, "
        "edges=357)"
    )


def test_reprs_stay_short_however_large_the_graph() -> None:
    graph = synthetic_graph(40, seed=1, poses_per_level=30, levels=3)
    target = graph.targets()[0]
    long_edge = Edge("car-0", "car-1", EdgeKind.SPATIAL, 12.5, np.zeros((5000, 3)))
    for thing in (graph, target, target.levels[0], graph.target_graph, long_edge):
        assert len(repr(thing)) < REPR_LIMIT, repr(thing)[:300]
    assert repr(long_edge).endswith("weight=12.50, via_points=5000)")
    assert str(target) == repr(target)
