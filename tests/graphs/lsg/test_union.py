"""The unified graph as the union of the local graphs (000 eq (5))."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.model import EdgeKind, Layer, LevelNode, LocalGraph, RobotNode
from seminspect.graphs.lsg.union import UnifiedGraph


def level(name: str, x: float) -> LevelNode:
    return LevelNode(f"car-0/{name}", name, 0, "car-0", np.array([x, 0.0, 0.0]), 0.0)


def test_a_parent_is_held_once_and_ids_are_unique() -> None:
    robot = RobotNode(np.zeros(3))
    union = UnifiedGraph(robot)
    target_graph = LocalGraph(Layer.TARGET, robot)
    a = level("Level-0", 3.0)
    union.add(target_graph, a)
    union.add(a.pose_graph, a)  # the same node again: a parent of its own local graph
    assert list(union.nodes) == ["robot", a.id]
    with pytest.raises(InvalidInputError, match="already exists"):
        union.add(target_graph, level("Level-0", 4.0))


def test_a_link_weighs_its_polyline_and_is_stored_along_its_key() -> None:
    robot = RobotNode(np.zeros(3))
    union = UnifiedGraph(robot)
    local = LocalGraph(Layer.LEVEL, robot)
    a, b = level("Level-0", 0.0), level("Level-1", 6.0)
    for node in (a, b):
        union.add(local, node)
    edge = union.link(local, b, a, via=[[3.0, 4.0, 0.0]])
    assert (edge.u, edge.v) == (a.id, b.id) and edge.kind is EdgeKind.SPATIAL
    assert edge.weight == pytest.approx(10.0)
    np.testing.assert_array_equal(edge.via, [[3.0, 4.0, 0.0]])
    assert union.edges[edge.key] is local.edges[edge.key] is edge
    with pytest.raises(InvalidInputError, match="finite"):
        union.link(local, a, b, via=[[np.nan, 0.0, 0.0]])


def test_discard_and_remove_take_nodes_with_their_edges() -> None:
    robot = RobotNode(np.zeros(3))
    union = UnifiedGraph(robot)
    local = LocalGraph(Layer.TARGET, robot)
    a, b = level("Level-0", 1.0), level("Level-1", 2.0)
    for node in (a, b):
        union.add(local, node)
        union.connect(local, robot, node, EdgeKind.SYMBOLIC)
    union.discard(local, a.id)
    assert list(union.nodes) == ["robot", b.id] and list(local.nodes) == ["robot", b.id]
    assert list(union.edges) == [("car-0/Level-1", "robot")] == list(local.edges)
    union.remove([b.id])
    assert list(union.nodes) == ["robot"] and not union.edges
