"""Nodes, edges and local graphs of the 3D Layered Semantic Graph (000 Sec IV-A).

Each layer is made of *local graphs*, one per parent node, exactly as the paper nests them:

* the Target graph ``G^T``: the robot (parent) and every target; symbolic robot-target edges and
  spatial edges between inspected targets;
* one Level graph ``G^L`` per inspected target: the target (parent) and its levels; symbolic
  target-level edges, spatial edges between adjacent levels;
* one Pose graph ``G^P`` per level: the level (parent) and its view poses; spatial edges from the
  level to its first and last pose and between consecutive poses;
* one Feature graph ``G^F`` per pose that observed features: the pose (parent) and its features,
  joined by symbolic edges.

A local graph holds its parent node too, so the same node object appears in two local graphs (as
a child in one, as the parent in the next). The unified graph is the union of all local graphs;
the difference between the summed local populations and the unified population is what Table 3
calls "reconciled".

Walking the hierarchy: ``target.levels``, ``level.poses`` and ``pose.features`` go down (in
order, children of the node's nested local graph); ``feature.pose``, ``pose.level`` and
``level.target`` go back up. They are properties: the downward ones build a short list from the
local graph, the upward ones follow the ``parent`` link that the graph sets when it inserts a
node. Every node's ``repr`` is one line naming its id and a few key attributes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import IDENTITY_QUAT, Quat, Vec3, yaw_from_quat


class Layer(str, Enum):
    """The four abstraction layers of 000 Sec III (the robot lives in the Target layer)."""

    TARGET = "target"
    LEVEL = "level"
    POSE = "pose"
    FEATURE = "feature"


class TargetStatus(str, Enum):
    """``V_D`` (detected, awaiting inspection) or ``V_I`` (inspected)."""

    DETECTED = "detected"
    INSPECTED = "inspected"


class EdgeKind(str, Enum):
    """Spatial edges have a metric weight and are traversable; symbolic ones model the hierarchy."""

    SPATIAL = "spatial"
    SYMBOLIC = "symbolic"


@dataclass(slots=True, eq=False, repr=False)
class RobotNode:
    """The parent of the Target layer, holding the robot state ``x_k``."""

    position: Vec3
    orientation: Quat = field(default_factory=IDENTITY_QUAT.copy)
    stamp: float = 0.0
    id: str = "robot"
    layer: Layer = Layer.TARGET

    @property
    def yaw(self) -> float:
        """Heading about +Z (rad), from :attr:`orientation`."""
        return yaw_from_quat(self.orientation)

    def __repr__(self) -> str:
        return (
            f"RobotNode(position={_xyz(self.position)}, yaw={self.yaw:.2f}, stamp={self.stamp:g})"
        )


@dataclass(slots=True, eq=False, repr=False)
class TargetNode:
    """A semantic target ``v^T`` with the attributes of 000 Sec IV-A."""

    id: str
    label: str
    index: int
    position: Vec3
    score: float
    mask_area: float
    image: str | None
    stamp: float
    utility: float = 0.0
    status: TargetStatus = TargetStatus.DETECTED
    observations: int = 1
    #: Containment polygon ``P`` (K x 2, metres), set when the inspection ends.
    polygon: NDArray[np.float64] | None = None
    #: The nested Level graph, created when the inspection starts.
    level_graph: LocalGraph | None = None
    layer: Layer = Layer.TARGET
    #: The robot, parent of the Target layer; set when the target enters a graph.
    parent: RobotNode | None = field(default=None, init=False)

    @property
    def name(self) -> str:
        """A target's name is its id (``car-1``)."""
        return self.id

    @property
    def inspected(self) -> bool:
        return self.status is TargetStatus.INSPECTED

    @property
    def levels(self) -> list[LevelNode]:
        """Level nodes in order (``Level-0`` first); empty until the inspection starts."""
        if self.level_graph is None:
            return []
        return [n for n in self.level_graph.children() if isinstance(n, LevelNode)]

    def __repr__(self) -> str:
        return (
            f"TargetNode({self.id!r}, label={self.label!r}, status={self.status.value!r}, "
            f"levels={len(self.levels)}, position={_xyz(self.position)}, score={self.score:.2f})"
        )


@dataclass(slots=True, eq=False, repr=False)
class LevelNode:
    """An inspection level ``v^L``: where the level started and its nested Pose graph."""

    id: str
    name: str
    index: int
    target_id: str
    position: Vec3
    stamp: float
    closed: bool = False
    #: The nested Pose graph; the level is its parent.
    pose_graph: LocalGraph = field(init=False)
    layer: Layer = Layer.LEVEL
    #: The target inspected at this level; set when the level enters a graph.
    parent: TargetNode | None = field(default=None, init=False)

    def __post_init__(self) -> None:
        self.pose_graph = LocalGraph(Layer.POSE, self)

    @property
    def poses(self) -> list[PoseNode]:
        """View poses in visiting order (``pose-0`` first)."""
        return [n for n in self.pose_graph.children() if isinstance(n, PoseNode)]

    @property
    def target(self) -> TargetNode:
        """The target this level belongs to."""
        return _parent_of(self, self.parent, "target")

    def __repr__(self) -> str:
        return f"LevelNode({self.id!r}, poses={len(self.poses)}, position={_xyz(self.position)})"


@dataclass(slots=True, eq=False, repr=False)
class PoseNode:
    """A tracked view pose ``v^P`` with its image and (when it saw features) its Feature graph."""

    id: str
    name: str
    index: int
    level_id: str
    position: Vec3
    orientation: Quat
    image: str | None
    stamp: float
    feature_graph: LocalGraph | None = None
    layer: Layer = Layer.POSE
    #: The level this pose was visited in; set when the pose enters a graph.
    parent: LevelNode | None = field(default=None, init=False)

    @property
    def features(self) -> list[FeatureNode]:
        """Features this pose observed best (after eq (10)); often none."""
        if self.feature_graph is None:
            return []
        return [n for n in self.feature_graph.children() if isinstance(n, FeatureNode)]

    @property
    def level(self) -> LevelNode:
        """The level this pose belongs to."""
        return _parent_of(self, self.parent, "level")

    @property
    def yaw(self) -> float:
        """Heading about +Z (rad), from :attr:`orientation`."""
        return yaw_from_quat(self.orientation)

    def __repr__(self) -> str:
        return (
            f"PoseNode({self.id!r}, features={len(self.features)}, "
            f"position={_xyz(self.position)}, yaw={self.yaw:.2f}, image={self.image!r})"
        )


@dataclass(slots=True, eq=False, repr=False)
class FeatureNode:
    """A semantic feature ``v^F`` observed from its pose (the best one, after eq (10))."""

    id: str
    name: str
    label: str
    pose_id: str
    position: Vec3
    score: float
    mask_area: float
    image: str | None
    layer: Layer = Layer.FEATURE
    #: The pose that observed the feature best; set when the feature enters a graph.
    parent: PoseNode | None = field(default=None, init=False)

    @property
    def pose(self) -> PoseNode:
        """The pose that observed this feature best."""
        return _parent_of(self, self.parent, "pose")

    @property
    def level(self) -> LevelNode:
        """The level the feature was named in (its id is ``<target>/<level>/<name>``)."""
        return self.pose.level

    def __repr__(self) -> str:
        return (
            f"FeatureNode({self.id!r}, label={self.label!r}, score={self.score:.2f}, "
            f"position={_xyz(self.position)})"
        )


Node = RobotNode | TargetNode | LevelNode | PoseNode | FeatureNode


@dataclass(slots=True, eq=False, repr=False)
class Edge:
    """An undirected edge. Spatial edges weigh their metric length; ``via`` is an optional
    polyline (M x 3) realising the edge when it is not a straight segment."""

    u: str
    v: str
    kind: EdgeKind
    weight: float = 0.0
    via: NDArray[np.float64] | None = None

    @property
    def key(self) -> tuple[str, str]:
        return edge_key(self.u, self.v)

    def __repr__(self) -> str:
        via = "" if self.via is None else f", via_points={len(self.via)}"
        return (
            f"Edge({self.u!r}, {self.v!r}, kind={self.kind.value!r}, weight={self.weight:.2f}{via})"
        )


def edge_key(u: str, v: str) -> tuple[str, str]:
    """Canonical key of an undirected edge."""
    return (u, v) if u <= v else (v, u)


@dataclass(slots=True, eq=False, repr=False)
class LocalGraph:
    """``G^l = (V^l, E^l, A^l)`` for one parent: its nodes (parent included) and edges."""

    layer: Layer
    parent: Node
    nodes: dict[str, Node] = field(default_factory=dict)
    edges: dict[tuple[str, str], Edge] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.nodes.setdefault(self.parent.id, self.parent)

    def children(self) -> list[Node]:
        """Nodes other than the parent, in insertion order."""
        return [node for node_id, node in self.nodes.items() if node_id != self.parent.id]

    def population(self) -> tuple[int, int]:
        """(nodes, edges) of this local graph, parent included."""
        return len(self.nodes), len(self.edges)

    def __repr__(self) -> str:
        return (
            f"LocalGraph(layer={self.layer.value!r}, parent={self.parent.id!r}, "
            f"nodes={len(self.nodes)}, edges={len(self.edges)})"
        )


P = TypeVar("P")


def _parent_of(node: Node, parent: P | None, what: str) -> P:
    """The parent a graph set on ``node``; a node built by hand and never inserted has none."""
    if parent is None:
        raise InvalidInputError(f"{node.id} is not in a graph, so it has no {what}")
    return parent


def _xyz(vector: NDArray[np.float64]) -> str:
    """A position as ``(x, y, z)`` to the centimetre, for reprs."""
    return "(" + ", ".join(f"{float(c):.2f}" for c in vector) + ")"
