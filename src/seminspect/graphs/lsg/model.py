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
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from seminspect.geometry.transforms import IDENTITY_QUAT, Quat, Vec3


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


@dataclass(slots=True, eq=False)
class RobotNode:
    """The parent of the Target layer, holding the robot state ``x_k``."""

    position: Vec3
    orientation: Quat = field(default_factory=IDENTITY_QUAT.copy)
    stamp: float = 0.0
    id: str = "robot"
    layer: Layer = Layer.TARGET


@dataclass(slots=True, eq=False)
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

    @property
    def inspected(self) -> bool:
        return self.status is TargetStatus.INSPECTED

    @property
    def levels(self) -> list[LevelNode]:
        """Level nodes in order (``Level-0`` first)."""
        if self.level_graph is None:
            return []
        return [n for n in self.level_graph.children() if isinstance(n, LevelNode)]


@dataclass(slots=True, eq=False)
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

    def __post_init__(self) -> None:
        self.pose_graph = LocalGraph(Layer.POSE, self)

    @property
    def poses(self) -> list[PoseNode]:
        return [n for n in self.pose_graph.children() if isinstance(n, PoseNode)]


@dataclass(slots=True, eq=False)
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

    @property
    def features(self) -> list[FeatureNode]:
        if self.feature_graph is None:
            return []
        return [n for n in self.feature_graph.children() if isinstance(n, FeatureNode)]


@dataclass(slots=True, eq=False)
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


Node = RobotNode | TargetNode | LevelNode | PoseNode | FeatureNode


@dataclass(slots=True, eq=False)
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


def edge_key(u: str, v: str) -> tuple[str, str]:
    """Canonical key of an undirected edge."""
    return (u, v) if u <= v else (v, u)


@dataclass(slots=True, eq=False)
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
