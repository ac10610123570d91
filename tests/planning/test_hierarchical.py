"""Invariants of the hierarchical planner, checked against flat Dijkstra (000 Sec V-C)."""

import math
from itertools import pairwise

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lsg_strategies import climbing_graphs, layered_graphs
from seminspect.core.errors import PlanningError
from seminspect.geometry.transforms import yaw_from_quat
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import FeatureNode, PoseNode
from seminspect.graphs.lsg.networkx_view import traversable_networkx
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.perception.observation import Observation
from seminspect.planning.hierarchical import HierarchicalPlanner


def goal_ids(graph: LayeredSemanticGraph) -> list[str]:
    return [n.id for n in graph.nodes() if n.id != "robot"]


@settings(max_examples=60, deadline=None)
@given(layered_graphs(), st.data())
def test_routes_are_connected_exact_and_end_at_the_queried_node(graph, data) -> None:
    flat = traversable_networkx(graph)
    planner = HierarchicalPlanner(graph)
    start = np.array(data.draw(st.tuples(*[st.floats(-30, 200)] * 3)))
    goal = data.draw(st.sampled_from(goal_ids(graph)))
    plan = planner.plan(goal, start)
    node = graph.node(goal)
    expected_end = node.pose_id if isinstance(node, FeatureNode) else goal
    if expected_end in {t.id for t in graph.targets()}:
        expected_end = LayeredSemanticGraph.entry_level(graph.target(goal)).id
    # starts at the robot, ends at the queried node
    np.testing.assert_array_equal(plan.waypoints[0], start)
    assert plan.node_path[0] == plan.localisation.node_id
    assert plan.node_path[-1] == expected_end
    np.testing.assert_allclose(plan.waypoints[-1], graph.node(expected_end).position)
    # connected: consecutive nodes are joined by a traversable edge
    for a, b in pairwise(plan.node_path):
        assert a == b or flat.has_edge(a, b), (a, b)
    # exact: the cost equals a flat Dijkstra search over the unified graph
    reference = nx.dijkstra_path_length(flat, plan.node_path[0], expected_end)
    assert plan.cost == pytest.approx(reference, rel=1e-9, abs=1e-9)
    first_leg = np.linalg.norm(plan.waypoints[1] - start) if len(plan.waypoints) > 1 else 0.0
    assert plan.length == pytest.approx(first_leg + plan.cost, rel=1e-9, abs=1e-9)
    # localised at the nearest traversable node
    nearest = min(np.linalg.norm(flat.nodes[n]["pos"] - start) for n in flat.nodes)
    assert plan.localisation.distance == pytest.approx(nearest)
    assert plan.target_route[0] == plan.localisation.target_id


def test_a_feature_query_ends_facing_the_feature() -> None:
    graph = synthetic_graph(2, poses_per_level=6, parts_per_pose=2)
    feature = graph.target("car-1").levels[0].poses[3].features[0]
    plan = HierarchicalPlanner(graph).query(
        f"Observe {feature.name} in Level-0 of car-1", start=[0, 0, 0]
    )
    pose = graph.node(feature.pose_id)
    assert plan.terminal_id == feature.id and plan.goal_id == feature.id
    expected = math.atan2(*(feature.position - pose.position)[1::-1])
    assert plan.final_yaw == pytest.approx(expected)
    plan = HierarchicalPlanner(graph).plan(pose.id)
    assert isinstance(pose, PoseNode) and plan.final_yaw == pytest.approx(
        yaw_from_quat(pose.orientation)
    )


def test_via_points_are_driven_between_targets() -> None:
    graph = synthetic_graph(2, poses_per_level=4, neighbours=0)
    edge = graph.edge("car-0", "car-1")
    graph.target_graph.edges.pop(edge.key)
    graph.unified.edges.pop(edge.key)  # replace the straight link by a detour
    graph.connect_targets("car-1", "car-0", via=[[5.0, 60.0, 0.7]])
    start = graph.target("car-0").levels[0].position
    plan = HierarchicalPlanner(graph).plan("car-1/Level-0", start)
    assert any(np.allclose(w, [5.0, 60.0, 0.7]) for w in plan.waypoints)
    assert plan.target_route == ("car-0", "car-1")
    assert plan.target_layer_length == pytest.approx(graph.edge("car-0", "car-1").weight)


def test_the_planner_follows_a_graph_that_grows() -> None:
    graph = synthetic_graph(2, poses_per_level=4)
    planner = HierarchicalPlanner(graph)
    assert planner.plan("car-1").target_route[-1] == "car-1"
    graph.register_target(Observation([90, 90, 0.7], label="truck", score=1, mask_area=1))
    graph.optimise_targets()
    graph.begin_inspection("truck-2", Observation.view_pose([87, 90, 0.7]))
    for angle in np.linspace(0, 2 * np.pi, 5)[:-1]:
        graph.register_pose(
            Observation.view_pose([90 + 3 * np.cos(angle), 90 + 3 * np.sin(angle), 0.7])
        )
    graph.finish_inspection()
    with pytest.raises(PlanningError, match="not connected in the Target layer"):
        planner.plan("truck-2", start=[0, 0, 0])
    graph.connect_targets("car-1", "truck-2")
    assert planner.plan("truck-2", start=[0, 0, 0]).target_route[-1] == "truck-2"


def test_unplannable_requests_say_why() -> None:
    graph = LayeredSemanticGraph()
    graph.register_target(Observation([5, 0, 0], label="car", score=1, mask_area=1))
    graph.optimise_targets()
    with pytest.raises(PlanningError, match="no route into it"):
        HierarchicalPlanner(graph).plan("car-0")
    with pytest.raises(PlanningError, match="not a place"):
        HierarchicalPlanner(synthetic_graph(1)).plan("robot")
    with pytest.raises(PlanningError, match="no inspected targets"):
        HierarchicalPlanner(graph).localise([0, 0, 0])


@settings(max_examples=40, deadline=None)
@given(climbing_graphs(), st.data())
def test_routes_follow_realised_level_edges_and_skip_open_rings(graph, data) -> None:
    flat = traversable_networkx(graph)
    planner = HierarchicalPlanner(graph)
    start = np.array(data.draw(st.tuples(*[st.floats(-30, 120)] * 3)))
    goal = data.draw(st.sampled_from([n.id for n in graph.nodes() if isinstance(n, PoseNode)]))
    plan = planner.plan(goal, start)
    assert plan.cost == pytest.approx(nx.dijkstra_path_length(flat, plan.node_path[0], goal))
    # the metric path holds every via point: its length is the graph cost plus the first leg
    first_leg = np.linalg.norm(plan.waypoints[1] - start)
    assert plan.length == pytest.approx(first_leg + plan.cost, rel=1e-9, abs=1e-9)
    for a, b in pairwise(plan.node_path):
        assert a == b or flat.has_edge(a, b), (a, b)


def test_a_level_edge_is_driven_through_its_via_points() -> None:
    graph = LayeredSemanticGraph()
    graph.register_target(Observation([5, 0, 1], label="building", score=1, mask_area=1))
    graph.optimise_targets()
    graph.begin_inspection("building-0", Observation.view_pose([0, 0, 1]))
    graph.register_pose(Observation.view_pose([0, 4, 1]))
    graph.register_pose(Observation.view_pose([4, 4, 1]))
    graph.close_level(close_ring=False)
    graph.begin_level(Observation.view_pose([4, 4, 4]), via=[[0, 4, 1], [4, 4, 1]])
    graph.register_pose(Observation.view_pose([6, 4, 4]))
    graph.finish_inspection()
    plan = HierarchicalPlanner(graph).plan("building-0/Level-1/pose-0", [0, 0, 1])
    assert plan.node_path == (
        "building-0/Level-0",
        "building-0/Level-1",
        "building-0/Level-1/pose-0",
    )
    np.testing.assert_allclose(
        plan.waypoints, [[0, 0, 1], [0, 0, 1], [0, 4, 1], [4, 4, 1], [4, 4, 4], [6, 4, 4]]
    )
    assert graph.edge("building-0/Level-0/pose-1", "building-0/Level-0") is None  # ring open
