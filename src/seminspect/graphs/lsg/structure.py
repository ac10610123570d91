"""The structure of a 3D Layered Semantic Graph: its nodes, edges and local graphs, how to walk
them and how to insert nodes (000 Sec IV).

:class:`GraphStructure` is what a graph *is*; :class:`~.graph.LayeredSemanticGraph` adds the
registration operators that build one from observations (000 Sec V). The walk:

* ``graph.targets()``, ``graph.levels()``, ``graph.poses()``, ``graph.features()``: every node of
  a layer, in order (methods: each builds a list);
* ``graph.target("car-1")``, ``graph.node("car-1/Level-0/hood-1")``: one node by name or id;
* from a node, ``target.levels``, ``level.poses``, ``pose.features`` down and ``feature.pose``,
  ``pose.level``, ``level.target`` up (properties, see :mod:`.model`).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.geometry.transforms import IDENTITY_QUAT, as_point, as_quaternion
from seminspect.graphs.lsg.model import (
    Edge,
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    LocalGraph,
    Node,
    PoseNode,
    RobotNode,
    TargetNode,
    TargetStatus,
    edge_key,
)
from seminspect.graphs.lsg.population import LayerPopulation, PopulationStats
from seminspect.graphs.lsg.union import UnifiedGraph

N = TypeVar("N", bound=Node)


class GraphStructure:
    """The local graph of every layer (nested as node attributes, as in the paper) and the
    unified graph ``G_k``, their union, with the robot as the Target layer's parent.

    Args:
        robot_position: initial robot position.
        robot_orientation: initial robot orientation (quaternion ``[x, y, z, w]``).
    """

    def __init__(
        self,
        robot_position: ArrayLike = (0.0, 0.0, 0.0),
        robot_orientation: ArrayLike = IDENTITY_QUAT,
    ) -> None:
        self.robot = RobotNode(
            as_point(robot_position, "robot position"),
            as_quaternion(robot_orientation, "robot orientation"),
        )
        self.target_graph = LocalGraph(Layer.TARGET, self.robot)
        #: The unified graph ``G_k``, the union of every local graph.
        self.unified = UnifiedGraph(self.robot)

    # ------------------------------------------------------------------ access
    def __contains__(self, node_id: object) -> bool:
        return node_id in self.unified.nodes

    def node(self, node_id: str) -> Node:
        """The node with this id (``car-1``, ``car-1/Level-0/hood-1``, ``robot``)."""
        try:
            return self.unified.nodes[node_id]
        except KeyError:
            raise unknown_name("node", node_id, self.unified.nodes) from None

    def nodes(self) -> Iterator[Node]:
        """Every node of the unified graph."""
        return iter(self.unified.nodes.values())

    def edges(self) -> Iterator[Edge]:
        """Every edge of the unified graph."""
        return iter(self.unified.edges.values())

    def edge(self, u: str, v: str) -> Edge | None:
        return self.unified.edges.get(edge_key(u, v))

    def targets(self, status: TargetStatus | None = None) -> list[TargetNode]:
        """Target nodes in registration order, optionally only those of one status."""
        return [
            node
            for node in self.target_graph.children()
            if isinstance(node, TargetNode) and (status is None or node.status is status)
        ]

    def target(self, name: str) -> TargetNode:
        """The target called ``name`` (case-insensitive); unknown names suggest close ones."""
        node = self.unified.nodes.get(name)
        if not isinstance(node, TargetNode):
            lowered = {t.id.lower(): t for t in self.targets()}
            node = lowered.get(name.lower())
        if node is None:
            raise unknown_name("target", name, (t.id for t in self.targets()))
        return node

    def levels(self) -> list[LevelNode]:
        """Every level, target by target in registration order, ``Level-0`` first."""
        return [level for target in self.targets() for level in target.levels]

    def poses(self) -> list[PoseNode]:
        """Every view pose, level by level in the order of :meth:`levels`."""
        return [pose for level in self.levels() for pose in level.poses]

    def features(self) -> list[FeatureNode]:
        """Every feature, pose by pose in the order of :meth:`poses`."""
        return [feature for pose in self.poses() for feature in pose.features]

    def edge_path(self, edge: Edge) -> NDArray[np.float64]:
        """The polyline (K x 3) realising a spatial edge from ``edge.u`` to ``edge.v``: the two
        nodes (for ``v_I - v_I`` edges, the targets' ``Level-0``) and any via points between."""
        ends = [self.node(edge.u), self.node(edge.v)]
        a, b = (self.entry_level(n) if isinstance(n, TargetNode) else n for n in ends)
        inner = edge.via if edge.via is not None else np.empty((0, 3))
        return np.vstack([a.position, inner, b.position])

    @staticmethod
    def entry_level(target: TargetNode) -> LevelNode:
        """``Level-0``: where the inspection started and where the target is entered and left."""
        levels = target.levels
        if not levels:
            raise InvalidInputError(f"{target.id} has no inspection levels")
        return levels[0]

    # ------------------------------------------------------------------ building from nodes
    # The registration operators build through these, and so does the file loader: one way to
    # put a node into its local graph and the unified graph, with the edges its layer implies.
    def add_target(self, target: TargetNode) -> TargetNode:
        """Insert a target node into the Target layer, joined to the robot."""
        self.unified.add(self.target_graph, target)
        target.parent = self.robot
        self.unified.connect(self.target_graph, self.robot, target, EdgeKind.SYMBOLIC)
        return target

    def add_level(self, level: LevelNode, via: ArrayLike | None = None) -> LevelNode:
        """Insert a level after the last level of its target (``level.target_id``), joined to
        the target and, through ``via`` (M x 3), to the previous level."""
        target = self._node_of(level.target_id, TargetNode)
        if target.level_graph is None:
            target.level_graph = LocalGraph(Layer.LEVEL, target)
        previous = target.levels[-1] if target.levels else None
        self.unified.add(target.level_graph, level)
        level.parent = target
        self.unified.connect(target.level_graph, target, level, EdgeKind.SYMBOLIC)
        if previous is not None:
            self.unified.link(target.level_graph, previous, level, via)
        elif via is not None:
            raise InvalidInputError(f"{level.id} is the first level; it has no edge to realise")
        return level

    def add_pose(self, pose: PoseNode) -> PoseNode:
        """Insert a view pose after the last pose of its level (``pose.level_id``), chained to
        that pose, or to the level for its first pose."""
        level = self._node_of(pose.level_id, LevelNode)
        poses = level.poses
        self.unified.add(level.pose_graph, pose)
        pose.parent = level
        self.unified.connect(
            level.pose_graph, poses[-1] if poses else level, pose, EdgeKind.SPATIAL
        )
        return pose

    def close_ring(self, level: LevelNode) -> None:
        """The spatial edge from a level's last pose back to the level, when it has two or
        more poses."""
        poses = level.poses
        if len(poses) > 1:
            self.unified.connect(level.pose_graph, poses[-1], level, EdgeKind.SPATIAL)

    def add_feature(self, feature: FeatureNode) -> FeatureNode:
        """Insert a feature into the Feature graph of the pose that observed it
        (``feature.pose_id``), joined to that pose."""
        pose = self._node_of(feature.pose_id, PoseNode)
        if pose.feature_graph is None:
            pose.feature_graph = LocalGraph(Layer.FEATURE, pose)
        self.unified.add(pose.feature_graph, feature)
        feature.parent = pose
        self.unified.connect(pose.feature_graph, pose, feature, EdgeKind.SYMBOLIC)
        return feature

    def _node_of(self, node_id: str, kind: type[N]) -> N:
        node = self.node(node_id)
        if not isinstance(node, kind):
            raise InvalidInputError(f"{node_id!r} is not a {kind.__name__}")
        return node

    # ------------------------------------------------------------------ statistics
    def local_graphs(self, layer: Layer) -> list[LocalGraph]:
        """Every local graph of ``layer``."""
        if layer is Layer.TARGET:
            return [self.target_graph]
        level_graphs = [t.level_graph for t in self.targets() if t.level_graph is not None]
        if layer is Layer.LEVEL:
            return level_graphs
        pose_graphs = [
            lv.pose_graph for g in level_graphs for lv in g.children() if isinstance(lv, LevelNode)
        ]
        if layer is Layer.POSE:
            return pose_graphs
        return [
            p.feature_graph
            for g in pose_graphs
            for p in g.children()
            if isinstance(p, PoseNode) and p.feature_graph is not None
        ]

    def population(self) -> PopulationStats:
        """The graph columns of 000 Table 3 for the graph as it is now."""
        targets = self.targets()
        return PopulationStats(
            target=LayerPopulation.summed(self.local_graphs(Layer.TARGET)),
            level=LayerPopulation.summed(self.local_graphs(Layer.LEVEL)),
            pose=LayerPopulation.summed(self.local_graphs(Layer.POSE)),
            feature=LayerPopulation.summed(self.local_graphs(Layer.FEATURE)),
            unified=LayerPopulation(len(self.unified.nodes), len(self.unified.edges)),
            targets_detected=len(targets),
            targets_inspected=sum(1 for t in targets if t.inspected),
        )

    def __repr__(self) -> str:
        targets = self.targets()
        inspected = sum(1 for t in targets if t.inspected)
        return (
            f"{type(self).__name__}(targets={len(targets)}, inspected={inspected}, "
            f"levels={len(self.levels())}, poses={len(self.poses())}, "
            f"features={len(self.features())}, edges={len(self.unified.edges)})"
        )
