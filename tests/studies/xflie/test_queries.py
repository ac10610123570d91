"""The planning study's query choice: spread by distance, every label's first feature first,
only targets the graph joins to the start."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.perception.observation import Observation
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.studies.xflie.queries import reachable_targets, select_queries


def test_queries_spread_from_the_nearest_to_the_farthest_target() -> None:
    graph = synthetic_graph(12, seed=1)
    start = np.zeros(3)
    queries = select_queries(graph, start, 5)
    assert queries == select_queries(graph, start, 5)  # deterministic
    by_distance = sorted(graph.targets(), key=lambda t: np.linalg.norm(t.position - start))
    named = [q.rsplit(" of ", 1)[1] for q in queries]
    assert named[0] == by_distance[0].id and named[-1] == by_distance[-1].id
    assert len(set(named)) == 5
    planner = HierarchicalPlanner(graph)
    for text in queries:
        assert text.startswith("Visit ") and " in Level-0 of " in text
        assert planner.query(text, start).terminal_id is not None  # a feature, found


def test_few_targets_are_asked_for_several_features() -> None:
    graph = synthetic_graph(2, seed=3, parts_per_pose=3)
    queries = select_queries(graph, np.zeros(3), 9)
    assert len(queries) == len(set(queries)) == 9
    first = [q.split(" in ")[0].removeprefix("Visit ") for q in queries[:4]]
    assert all(name.endswith("-1") for name in first)  # every label's first feature first
    with pytest.raises(InvalidInputError, match="positive"):
        select_queries(graph, np.zeros(3), 0)


def test_queries_keep_to_targets_the_graph_joins_to_the_start() -> None:
    graph = LayeredSemanticGraph()
    for x in (0.0, 60.0):  # two cars, inspected, never joined in the Target layer
        graph.register_target(Observation([x, 0, 0.7], label="car", mask_area=1))
    graph.optimise_targets()
    for target, x in zip(graph.targets(), (0.0, 60.0), strict=True):
        graph.begin_inspection(target.id, Observation.view_pose([x - 3, 0, 0.7]))
        for dx, dy in ((0, 3), (3, 0), (0, -3)):
            graph.register_pose(Observation.view_pose([x + dx, dy, 0.7]))
            graph.register_feature(Observation([x + dx / 2, dy / 2, 0.7], label="hood"))
        graph.finish_inspection()
    planner = HierarchicalPlanner(graph)
    start = np.array([-5.0, 0.0, 0.7])
    assert reachable_targets(planner, start) == {"car-0"}
    queries = select_queries(graph, start, 4, reachable={"car-0"})
    assert queries and all(q.endswith("of car-0") for q in queries)
    assert any(q.endswith("of car-1") for q in select_queries(graph, start, 4))
