"""Construction of the 3DLSG through its registration operators (000 Sec IV-V)."""

import math
from itertools import pairwise

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import (
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    PoseNode,
    TargetNode,
    TargetStatus,
)
from seminspect.graphs.lsg.optimisation import Outcome
from seminspect.perception.observation import Observation

RING = [(10, -3), (13, 0), (10, 3), (7, 0)]  # four view poses around a car at (10, 0)


def small_graph() -> LayeredSemanticGraph:
    graph = LayeredSemanticGraph(robot_position=[0, 0, 0.7])
    graph.register_target(Observation([9.0, 0.4, 0.7], label="car", score=0.9, mask_area=5000))
    graph.register_target(Observation([0.0, 20.0, 0.7], label="truck", score=0.8, mask_area=9000))
    graph.optimise_targets()
    graph.begin_inspection("car-0", Observation.view_pose([7.0, 0.0, 0.7]))
    for i, (x, y) in enumerate(RING):
        graph.register_pose(
            Observation.view_pose([x, y, 0.7], quat_from_yaw(0.0), image=f"{i}.png")
        )
        if i == 1:
            graph.register_feature(
                Observation([11.8, 0.0, 0.8], label="hood", score=0.7, mask_area=900)
            )
            graph.register_feature(
                Observation([12.2, 0.1, 0.5], label="front-bumper", score=0.6, mask_area=400)
            )
        if i == 2:
            graph.register_feature(
                Observation([11.5, 0.2, 0.8], label="hood", score=0.95, mask_area=2000)
            )
    graph.finish_inspection()
    return graph


def test_names_follow_the_numbering_rules() -> None:
    graph = small_graph()
    assert [t.id for t in graph.targets()] == ["car-0", "truck-1"]
    car = graph.target("CAR-0")
    assert [lv.id for lv in car.levels] == ["car-0/Level-0"]
    assert [p.name for p in car.levels[0].poses] == ["pose-0", "pose-1", "pose-2", "pose-3"]
    features = {f.id: f.pose_id for p in car.levels[0].poses for f in p.features}
    assert features == {
        "car-0/Level-0/front-bumper-1": "car-0/Level-0/pose-1",
        "car-0/Level-0/hood-1": "car-0/Level-0/pose-2",  # the 0.95 observation won eq (10)
    }


def test_edges_follow_000_sec_iv() -> None:
    graph = small_graph()
    kinds = {(e.u, e.v): e.kind for e in graph.edges()}
    assert kinds[("car-0", "robot")] is EdgeKind.SYMBOLIC
    assert kinds[("robot", "truck-1")] is EdgeKind.SYMBOLIC
    assert kinds[("car-0", "car-0/Level-0")] is EdgeKind.SYMBOLIC
    level = "car-0/Level-0"
    chain = [level, *(f"{level}/pose-{i}" for i in range(4)), level]  # closed through the level
    for a, b in pairwise(chain):
        edge = graph.edge(a, b)
        assert edge is not None and edge.kind is EdgeKind.SPATIAL
        assert edge.weight == pytest.approx(
            np.linalg.norm(graph.node(a).position - graph.node(b).position)
        )
    assert graph.edge(f"{level}/pose-2", f"{level}/hood-1").kind is EdgeKind.SYMBOLIC


def test_population_has_the_shape_of_table_3() -> None:
    stats = small_graph().population()
    assert (stats.target.nodes, stats.target.edges) == (3, 2)  # robot + 2 targets
    assert (stats.level.nodes, stats.level.edges) == (2, 1)  # car-0 + Level-0
    assert (stats.pose.nodes, stats.pose.edges) == (5, 5)  # Level-0 + 4 poses, closed ring
    assert (stats.feature.nodes, stats.feature.edges) == (4, 2)  # two feature graphs
    assert (stats.total.nodes, stats.total.edges) == (14, 10)
    assert (stats.unified.nodes, stats.unified.edges) == (10, 10)
    assert stats.reconciled_pct == pytest.approx(100 * 4 / 14)
    assert (stats.targets_detected, stats.targets_inspected) == (2, 1)


def test_inspection_builds_the_polygon_and_refines_the_position() -> None:
    car = small_graph().target("car-0")
    assert car.status is TargetStatus.INSPECTED
    np.testing.assert_array_equal(car.polygon, np.array(RING, dtype=float))
    np.testing.assert_allclose(car.position, [10.0, 0.0, 0.7])  # centroid; height kept


def test_duplicates_and_detections_inside_inspected_targets_are_filtered() -> None:
    graph = small_graph()
    graph.update_robot([0, 0, 0.7], quat_from_yaw(0.0), stamp=1.0)
    graph.register_target(Observation([10.5, 1.0, 0.7], label="car", score=0.9, mask_area=100))
    graph.register_target(Observation([1.0, 21.0, 0.7], label="truck", score=0.9, mask_area=99999))
    graph.register_target(Observation([30.0, 0.0, 0.7], label="car", score=0.9, mask_area=10))
    update = graph.optimise_targets()
    outcomes = [d.outcome for d in update.decisions]
    assert outcomes == [Outcome.INSIDE_POLYGON, Outcome.MERGED, Outcome.ADDED]
    assert update.resolved == (None, "truck-1", "car-2")
    truck = graph.target("truck-1")
    assert truck.observations == 2 and truck.mask_area == 99999  # the fuller view took over
    np.testing.assert_allclose(truck.position, [1.0, 21.0, 0.7])


def test_levels_chain_with_spatial_edges() -> None:
    graph = LayeredSemanticGraph()
    graph.register_target(Observation([5, 0, 1], label="building", score=1, mask_area=1))
    graph.optimise_targets()
    graph.begin_inspection("building-0", Observation.view_pose([0, 0, 1]))
    graph.register_pose(Observation.view_pose([0, 1, 1]))
    graph.begin_level(Observation.view_pose([0, 1, 4]))
    graph.register_pose(Observation.view_pose([0, 2, 4]))
    graph.finish_inspection()
    edge = graph.edge("building-0/Level-0", "building-0/Level-1")
    assert edge.kind is EdgeKind.SPATIAL and edge.weight == pytest.approx(math.sqrt(1 + 9))
    assert graph.target("building-0").polygon is None  # two poses cannot enclose anything
    assert [g.parent.id for g in graph.local_graphs(Layer.POSE)] == [
        "building-0/Level-0",
        "building-0/Level-1",
    ]


def test_misuse_gives_clear_errors() -> None:
    graph = small_graph()
    with pytest.raises(InvalidInputError, match="no inspection in progress"):
        graph.register_pose(Observation.view_pose([0, 0, 0]))
    with pytest.raises(InvalidInputError, match="already inspected"):
        graph.begin_inspection("car-0", Observation.view_pose([0, 0, 0]))
    with pytest.raises(UnknownNameError, match="truck-1"):
        graph.target("truck-2")
    with pytest.raises(InvalidInputError, match="not inspected"):
        graph.connect_targets("car-0", "truck-1")
    graph.begin_inspection("truck-1", Observation.view_pose([0, 17, 0.7]))
    with pytest.raises(InvalidInputError, match="register a pose"):
        graph.register_feature(Observation([0, 20, 1], label="hood", score=1, mask_area=1))
    with pytest.raises(InvalidInputError, match="already inspecting"):
        graph.begin_inspection("truck-1", Observation.view_pose([0, 0, 0]))
    with pytest.raises(InvalidInputError, match="invalid semantic label"):
        graph.register_target(Observation([0, 0, 0], label="a/b"))
    with pytest.raises(InvalidInputError, match="robot position"):
        graph.update_robot([0, float("nan"), 0], [0, 0, 0, 1], 0.0)


def test_connect_targets_weighs_the_via_polyline() -> None:
    graph = small_graph()
    graph.begin_inspection("truck-1", Observation.view_pose([0.0, 17.0, 0.7]))
    graph.register_pose(Observation.view_pose([3.0, 20.0, 0.7]))
    graph.finish_inspection()
    edge = graph.connect_targets("truck-1", "car-0", via=[[0.0, 0.0, 0.7]])
    # Level-0 of truck-1 (0,17) -> (0,0) -> Level-0 of car-0 (7,0)
    assert edge.weight == pytest.approx(17 + 7)
    assert (edge.u, edge.v) == ("car-0", "truck-1")
    np.testing.assert_allclose(edge.via, [[0.0, 0.0, 0.7]])


def test_discarding_a_false_detection_removes_it_everywhere() -> None:
    graph = small_graph()
    before = graph.population()
    graph.discard_target("truck-1")
    after = graph.population()
    assert "truck-1" not in graph and [t.id for t in graph.targets()] == ["car-0"]
    assert graph.edge("robot", "truck-1") is None
    assert (after.unified.nodes, after.unified.edges) == (
        before.unified.nodes - 1,
        before.unified.edges - 1,
    )
    with pytest.raises(InvalidInputError, match="only detected targets"):
        graph.discard_target("car-0")
    graph.register_target(Observation([0, 20, 0.7], label="truck", score=0.9, mask_area=10))
    graph.optimise_targets()
    assert graph.targets()[-1].id == "truck-2"  # numbers are never reused


def test_finishing_an_inspection_prunes_its_earlier_re_detections() -> None:
    graph = LayeredSemanticGraph(robot_position=[0, 0, 0.7])
    for x, y, area in ((9.0, 0.4, 5000), (15.5, 0.0, 400), (30.0, 0.0, 900)):
        graph.register_target(Observation([x, y, 0.7], label="car", score=0.9, mask_area=area))
    graph.optimise_targets()  # car-1 sits 6.5 m from car-0's estimate: not merged then
    graph.begin_inspection("car-0", Observation.view_pose([7.0, 0.0, 0.7]))
    for x, y in ((10, -5), (17, -5), (17, 5), (10, 5)):  # a long vehicle, seen all round
        graph.register_pose(Observation.view_pose([x, y, 0.7]))
    graph.finish_inspection()
    assert graph.pruned == ("car-1",)  # inside the containment polygon
    assert [t.id for t in graph.targets()] == ["car-0", "car-2"]


def test_an_inspection_too_short_for_a_polygon_is_cancelled() -> None:
    graph = LayeredSemanticGraph(robot_position=[0, 0, 0.7])
    graph.register_target(Observation([9.0, 0.0, 0.7], label="car", score=0.9, mask_area=500))
    graph.optimise_targets()
    before = graph.population()
    graph.begin_inspection("car-0", Observation.view_pose([7.0, 0.0, 0.7]))
    graph.register_pose(Observation.view_pose([7.0, 1.0, 0.7]))
    graph.register_feature(Observation([9.0, 0.5, 0.8], label="hood", score=0.8, mask_area=10))
    assert graph.abort_inspection() is None
    car = graph.target("car-0")
    assert car.status is TargetStatus.DETECTED and car.levels == [] and graph.inspecting is None
    assert graph.population() == before
    graph.begin_inspection("car-0", Observation.view_pose([7.0, 0.0, 0.7]))  # can start again
    for x, y in RING:
        graph.register_pose(Observation.view_pose([x, y, 0.7]))
    assert graph.abort_inspection() is car and car.inspected


def test_the_polygon_can_come_from_a_later_level() -> None:
    graph = LayeredSemanticGraph()
    graph.register_target(Observation([10, 0, 3], label="building", score=1, mask_area=1))
    graph.optimise_targets()
    graph.begin_inspection("building-0", Observation.view_pose([6, 0, 2]))
    for x, y in ((6, -2), (8, -4)):  # Level-0 broke off after two views
        graph.register_pose(Observation.view_pose([x, y, 2]))
    graph.begin_level(Observation.view_pose([6, 0, 5]))
    for x, y in RING:
        graph.register_pose(Observation.view_pose([x, y, 5]))
    with pytest.raises(InvalidInputError, match="no level 2"):
        graph.finish_inspection(polygon_level=2)
    building = graph.finish_inspection(polygon_level=1)
    np.testing.assert_allclose(building.position, [10.0, 0.0, 3.0])


def test_edge_paths_run_through_entry_levels_and_via_points() -> None:
    graph = small_graph()
    graph.begin_inspection("truck-1", Observation.view_pose([0.0, 17.0, 0.7]))
    graph.register_pose(Observation.view_pose([3.0, 20.0, 0.7]))
    graph.finish_inspection()
    edge = graph.connect_targets("truck-1", "car-0", via=[[0.0, 0.0, 0.7]])
    np.testing.assert_allclose(graph.edge_path(edge), [[7, 0, 0.7], [0, 0, 0.7], [0, 17, 0.7]])
    ring = graph.edge("car-0/Level-0/pose-3", "car-0/Level-0")
    np.testing.assert_allclose(graph.edge_path(ring), [[7, 0, 0.7], [7, 0, 0.7]])


def _pose(level_id: str, index: int, position) -> PoseNode:
    name = f"Pose-{index}"
    return PoseNode(
        f"{level_id}/{name}", name, index, level_id, np.asarray(position, float),
        np.array([0.0, 0.0, 0.0, 1.0]), None, 0.0,
    )  # fmt: skip


def _feature(pose_id: str, label: str) -> FeatureNode:
    level_id = pose_id.rsplit("/", 1)[0]
    name = f"{label}-1"
    return FeatureNode(f"{level_id}/{name}", name, label, pose_id, np.ones(3), 0.9, 10, None)


def test_nodes_built_by_hand_get_the_edges_of_their_layer() -> None:
    graph = LayeredSemanticGraph(robot_position=[0, 0, 0.7])
    car = graph.add_target(
        TargetNode("car-0", "car", 0, np.array([5.0, 0.0, 0.7]), 0.9, 100, None, 0.0)
    )
    assert graph.edge("robot", "car-0").kind is EdgeKind.SYMBOLIC
    level = LevelNode("car-0/Level-0", "Level-0", 0, "car-0", np.zeros(3), 0.0)
    with pytest.raises(InvalidInputError, match="first level"):
        graph.add_level(level, [[1.0, 1.0, 1.0]])
    first = graph.add_pose(_pose(level.id, 0, [1.0, 1.0, 1.0]))
    second = graph.add_pose(_pose(level.id, 1, [2.0, 1.0, 1.0]))
    graph.close_ring(level)
    assert [p.id for p in car.levels[0].poses] == [first.id, second.id]
    for u, v in ((level.id, first.id), (first.id, second.id), (level.id, second.id)):
        assert graph.edge(u, v).kind is EdgeKind.SPATIAL
    hood = graph.add_feature(_feature(second.id, "hood"))
    assert graph.edge(second.id, hood.id).kind is EdgeKind.SYMBOLIC
    with pytest.raises(InvalidInputError, match="is not a PoseNode"):
        graph.add_feature(
            FeatureNode("car-0/trunk-1", "trunk-1", "trunk", level.id, np.ones(3), 0.9, 10, None)
        )


def test_a_polygon_grown_from_every_level_covers_a_building_circled_in_part() -> None:
    """A 20 x 10 m building centred at (10, 0): Level-0 circled only its west half, Level-1
    its east half."""

    def inspected(every_level):
        graph = LayeredSemanticGraph()
        graph.register_target(Observation([4, 0, 3], label="building", score=1, mask_area=1))
        graph.optimise_targets()
        graph.begin_inspection("building-0", Observation.view_pose([-4, 0, 2]))
        for x, y in ((-4, -9), (5, -9), (5, 9), (-4, 9)):
            graph.register_pose(Observation.view_pose([x, y, 2]))
        graph.begin_level(Observation.view_pose([24, 0, 5]))
        for x, y in ((15, -9), (24, -9), (24, 9), (15, 9)):
            graph.register_pose(Observation.view_pose([x, y, 5]))
        return graph, graph.finish_inspection(every_level=every_level)

    _, first_ring_only = inspected(every_level=False)
    assert first_ring_only.position[0] < 1.0  # Level-0's ring: the west half only
    graph, building = inspected(every_level=True)
    np.testing.assert_allclose(building.position[:2], [10.0, 0.0], atol=1e-9)
    # a far-side detection now falls inside the polygon and is not a new target
    graph.update_robot([28, 0, 2], quat_from_yaw(math.pi), 1.0)
    graph.register_target(Observation([19, 1, 3], label="building", score=1, mask_area=9))
    update = graph.optimise_targets()
    assert update.decisions[0].outcome is Outcome.INSIDE_POLYGON
    assert len(graph.targets()) == 1
