"""The 3D Layered Semantic Graph and its incremental construction (000 Sec IV and V).

:class:`LayeredSemanticGraph` keeps the local graph of every layer (nested as node attributes, as
in the paper) and the unified graph ``G_k``, their union. Each registration operator ``R``
updates one local graph and merges the change into the unified graph:

=====================  ==========================================  =============
operator               what it registers                           paper
=====================  ==========================================  =============
``register_target``    a detection into the unoptimised ``G~^T``   eq (3)
``optimise_targets``   Φ on ``G~^T``, then the union into ``G_k``  eqs (4), (5)
``begin_inspection``   ``Level-0`` of the selected target          eq (7)
``begin_level``        the next inspection level                   eq (7)
``register_pose``      a tracked view pose                         eq (9)
``register_feature``   a feature into the interim ``G~^PF``        Sec V-B
``close_level``        Φ on ``G~^PF``, then the union              eq (10)
``finish_inspection``  containment polygon, centroid refinement    Sec V-B
=====================  ==========================================  =============
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.core.params import PRESETS, InspectionParams
from seminspect.geometry.polygons import (
    hull_polygon,
    polygon_centroid,
    polygon_contains,
    ring_polygon,
)
from seminspect.geometry.transforms import IDENTITY_QUAT, as_point, as_quaternion, yaw_from_quat
from seminspect.graphs.lsg import naming
from seminspect.graphs.lsg.claims import TargetClaims
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
)
from seminspect.graphs.lsg.optimisation import (
    ExistingTarget,
    InspectedView,
    Outcome,
    PoseFeaturePair,
    TargetDecision,
    optimise_features,
    optimise_targets,
)
from seminspect.perception.observation import Observation

N = TypeVar("N", bound=Node)


@dataclass(frozen=True, slots=True)
class LayerPopulation:
    """Nodes and edges summed over the local graphs of one layer."""

    nodes: int
    edges: int

    def __str__(self) -> str:
        return f"{self.nodes}/{self.edges}"


@dataclass(frozen=True, slots=True)
class PopulationStats:
    """The graph columns of 000 Table 3.

    ``reconciled_pct`` is the share of local-graph node registrations that the union merged into
    a node already present: ``100 * (sum of local nodes - unified nodes) / sum of local nodes``.
    A node is counted once per local graph it belongs to (a level is a child in its target's
    Level graph and the parent of its Pose graph), so the union reconciles exactly the parents.
    """

    target: LayerPopulation
    level: LayerPopulation
    pose: LayerPopulation
    feature: LayerPopulation
    unified: LayerPopulation
    targets_detected: int
    targets_inspected: int

    @property
    def total(self) -> LayerPopulation:
        layers = (self.target, self.level, self.pose, self.feature)
        return LayerPopulation(sum(p.nodes for p in layers), sum(p.edges for p in layers))

    @property
    def reconciled_pct(self) -> float:
        total = self.total.nodes
        return 100.0 * (total - self.unified.nodes) / total if total else 0.0


@dataclass(frozen=True, slots=True)
class TargetUpdate:
    """What one application of eq (4) + (5) did."""

    decisions: tuple[TargetDecision, ...]
    #: Node id for each candidate: the node it became or merged into; None when rejected.
    resolved: tuple[str | None, ...]

    def count(self, outcome: Outcome) -> int:
        return sum(1 for d in self.decisions if d.outcome is outcome)

    @property
    def added(self) -> list[str]:
        return [
            r
            for d, r in zip(self.decisions, self.resolved, strict=True)
            if d.outcome is Outcome.ADDED and r
        ]


@dataclass(frozen=True, slots=True)
class LevelSummary:
    """What closing a level (eq (10)) did."""

    level_id: str
    registered: int
    kept: tuple[str, ...]

    @property
    def pruned(self) -> int:
        return self.registered - len(self.kept)


@dataclass(slots=True)
class _Inspection:
    """The inspection in progress: its target, current level and interim ``G~^PF``."""

    target: TargetNode
    level: LevelNode
    interim: list[PoseFeaturePair] = field(default_factory=list)


class LayeredSemanticGraph:
    """A 3D Layered Semantic Graph, built incrementally from observations.

    Args:
        params: the parameters of 000 Tables 1-2 (uniqueness radii, range, field of view).
        robot_position: initial robot position.
        robot_orientation: initial robot orientation (quaternion ``[x, y, z, w]``).
    """

    def __init__(
        self,
        params: InspectionParams | None = None,
        robot_position: ArrayLike = (0.0, 0.0, 0.0),
        robot_orientation: ArrayLike = IDENTITY_QUAT,
    ) -> None:
        self.params = params if params is not None else PRESETS["urban-simulated"]
        self.robot = RobotNode(
            as_point(robot_position, "robot position"),
            as_quaternion(robot_orientation, "robot orientation"),
        )
        self.target_graph = LocalGraph(Layer.TARGET, self.robot)
        self._nodes: dict[str, Node] = {self.robot.id: self.robot}
        self._edges: dict[tuple[str, str], Edge] = {}
        self._pending: list[Observation] = []
        self._inspection: _Inspection | None = None
        #: Detected targets removed by the last :meth:`finish_inspection`.
        self.pruned: tuple[str, ...] = ()
        self.next_target_index = 0
        #: Incremented on every change; planners use it to invalidate their caches.
        self.revision = 0
        #: Which robot has taken which target, when several robots share this graph.
        self.claims = TargetClaims()

    # ------------------------------------------------------------------ access
    def __contains__(self, node_id: object) -> bool:
        return node_id in self._nodes

    def node(self, node_id: str) -> Node:
        """The node with this id (``car-1``, ``car-1/Level-0/hood-1``, ``robot``)."""
        try:
            return self._nodes[node_id]
        except KeyError:
            raise unknown_name("node", node_id, self._nodes) from None

    def nodes(self) -> Iterator[Node]:
        """Every node of the unified graph."""
        return iter(self._nodes.values())

    def edges(self) -> Iterator[Edge]:
        """Every edge of the unified graph."""
        return iter(self._edges.values())

    def edge(self, u: str, v: str) -> Edge | None:
        return self._edges.get((u, v) if u <= v else (v, u))

    def targets(self, status: TargetStatus | None = None) -> list[TargetNode]:
        """Target nodes in registration order, optionally only those of one status."""
        return [
            node
            for node in self.target_graph.children()
            if isinstance(node, TargetNode) and (status is None or node.status is status)
        ]

    def target(self, name: str) -> TargetNode:
        """The target called ``name`` (case-insensitive); unknown names suggest close ones."""
        node = self._nodes.get(name)
        if not isinstance(node, TargetNode):
            lowered = {t.id.lower(): t for t in self.targets()}
            node = lowered.get(name.lower())
        if node is None:
            raise unknown_name("target", name, (t.id for t in self.targets()))
        return node

    @property
    def inspecting(self) -> TargetNode | None:
        """The target under inspection, if any."""
        return self._inspection.target if self._inspection else None

    @property
    def current_level(self) -> LevelNode | None:
        return self._inspection.level if self._inspection else None

    @property
    def pending(self) -> Sequence[Observation]:
        """Detections registered into ``G~^T`` and not yet optimised."""
        return tuple(self._pending)

    # ------------------------------------------------------------------ robot
    def update_robot(self, position: ArrayLike, orientation: ArrayLike, stamp: float) -> None:
        """Store the robot state ``x_k`` on the Target layer's parent node."""
        self.robot.position = as_point(position, "robot position")
        self.robot.orientation = as_quaternion(orientation, "robot orientation")
        if not math.isfinite(stamp):
            raise InvalidInputError(f"robot stamp must be finite, got {stamp}")
        self.robot.stamp = float(stamp)

    # ------------------------------------------------------------------ Target layer
    def register_target(self, z: Observation) -> int:
        """R of eq (3): add a detection to the unoptimised Target graph; returns its slot."""
        naming.check_label(z.label)
        self._pending.append(z)
        return len(self._pending) - 1

    def optimise_targets(self, reject_near_inspected: bool = True) -> TargetUpdate:
        """Φ of eq (4) over the registered detections, then the union of eq (5).

        Uses the robot state stored by :meth:`update_robot` for the range and field-of-view test.
        """
        candidates, self._pending = self._pending, []
        inspected = [
            InspectedView(t.id, t.position, t.polygon) for t in self.targets(TargetStatus.INSPECTED)
        ]
        existing = [ExistingTarget(t.id, t.position) for t in self.targets(TargetStatus.DETECTED)]
        decisions = optimise_targets(
            candidates,
            existing,
            inspected,
            robot_position=self.robot.position,
            robot_yaw=yaw_from_quat(self.robot.orientation),
            d_check_T=self.params.d_check_T,
            d_max=self.params.d_max,
            fov_rad=self.params.fov_rad,
            reject_near_inspected=reject_near_inspected,
        )
        resolved: list[str | None] = [None] * len(candidates)
        for i, decision in enumerate(decisions):  # new nodes are numbered in registration order
            if decision.outcome is Outcome.ADDED:
                resolved[i] = self._add_target(candidates[i]).id
        for i, decision in enumerate(decisions):
            if decision.outcome is Outcome.MERGED:
                into = decision.target_id
                if decision.into_candidate is not None:
                    into = resolved[decision.into_candidate]
                target = self._nodes[into]  # type: ignore[index]
                assert isinstance(target, TargetNode)
                self._merge_detection(target, candidates[i])
                resolved[i] = into
        if candidates:
            self.revision += 1
        return TargetUpdate(tuple(decisions), tuple(resolved))

    def _add_target(self, z: Observation) -> TargetNode:
        index = self.next_target_index
        self.next_target_index += 1
        target = TargetNode(
            id=naming.target_name(z.label, index),
            label=z.label,
            index=index,
            position=z.position.copy(),
            score=z.score,
            mask_area=z.mask_area,
            image=z.image,
            stamp=z.stamp,
        )
        return self.add_target(target)

    @staticmethod
    def _merge_detection(target: TargetNode, z: Observation) -> None:
        """A duplicate detection: the larger mask (closer, fuller view) sets the attributes."""
        target.observations += 1
        if z.mask_area > target.mask_area and not target.inspected:
            target.position = z.position.copy()
            target.score = z.score
            target.mask_area = z.mask_area
            target.image = z.image
            target.stamp = z.stamp

    def discard_target(self, target_id: str) -> TargetNode:
        """Remove a detected (uninspected) target found to be invalid, e.g. a false detection
        that is not there when the robot comes to look; Φ's removal of invalid nodes (eq 4)."""
        target = self.target(target_id)
        if target.inspected or target is self.inspecting:
            raise InvalidInputError(
                f"{target.id} is inspected; only detected targets are discarded"
            )
        for key in [k for k in self.target_graph.edges if target.id in k]:
            del self.target_graph.edges[key]
            del self._edges[key]
        del self.target_graph.nodes[target.id]
        del self._nodes[target.id]
        self.revision += 1
        return target

    def connect_targets(self, a: str, b: str, via: ArrayLike | None = None) -> Edge:
        """Spatial ``v_I - v_I`` edge between two inspected targets.

        The metric realisation of the edge runs from ``Level-0`` of ``a`` through the optional
        ``via`` points (M x 3, e.g. the simplified path the robot drove) to ``Level-0`` of ``b``;
        its weight is that polyline's length, which is the Euclidean distance between the two
        entry points when there is no ``via``.
        """
        first, second = self.target(a), self.target(b)
        for node in (first, second):
            if not node.inspected:
                raise InvalidInputError(f"{node.id} is not inspected; only v_I - v_I edges exist")
        if first is second:
            raise InvalidInputError(f"cannot connect {first.id} to itself")
        ends = (self.entry_level(first).position, self.entry_level(second).position)
        edge = self._link(self.target_graph, first, second, via, ends)
        self.revision += 1
        return edge

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

    # ------------------------------------------------------------------ inspection
    def begin_inspection(self, target_id: str, z: Observation) -> LevelNode:
        """Start inspecting a detected target: R of eq (7) creates its Level graph and Level-0."""
        if self._inspection is not None:
            raise InvalidInputError(f"already inspecting {self._inspection.target.id}")
        target = self.target(target_id)
        if target.inspected:
            raise InvalidInputError(f"{target.id} is already inspected")
        target.level_graph = LocalGraph(Layer.LEVEL, target)
        level = self._new_level(target, z)
        self._inspection = _Inspection(target, level)
        return level

    def begin_level(self, z: Observation, via: ArrayLike | None = None) -> LevelNode:
        """Close the current level (eq (10)) and start the next one at ``z`` (eq (7)).

        The spatial edge from the previous level is realised through ``via`` (M x 3, e.g. the
        route the robot took to the new level's start) when given.
        """
        inspection = self._require_inspection()
        self.close_level()
        level = self._new_level(inspection.target, z, via)
        inspection.level = level
        return level

    def _new_level(
        self, target: TargetNode, z: Observation, via: ArrayLike | None = None
    ) -> LevelNode:
        index = len(target.levels)
        level = LevelNode(
            id=naming.join(target.id, naming.level_name(index)),
            name=naming.level_name(index),
            index=index,
            target_id=target.id,
            position=z.position.copy(),
            stamp=z.stamp,
        )
        self.add_level(level, via)
        self.revision += 1
        return level

    def register_pose(self, z: Observation) -> PoseNode:
        """R of eq (9): a tracked view pose, chained to the previous one (or to its level)."""
        level = self._require_inspection().level
        if level.closed:
            raise InvalidInputError(f"{level.id} is closed")
        poses = level.poses
        index = len(poses)
        pose = PoseNode(
            id=naming.join(level.id, naming.pose_name(index)),
            name=naming.pose_name(index),
            index=index,
            level_id=level.id,
            position=z.position.copy(),
            orientation=z.orientation.copy(),
            image=z.image,
            stamp=z.stamp,
        )
        self.add_pose(pose)
        self.revision += 1
        return pose

    def register_feature(self, z: Observation, pose_id: str | None = None) -> None:
        """Add a feature observation to the interim ``G~^PF`` of the current level.

        ``pose_id`` defaults to the latest pose of the level.
        """
        inspection = self._require_inspection()
        naming.check_label(z.label)
        poses = inspection.level.poses
        if pose_id is None:
            if not poses:
                raise InvalidInputError("register a pose before the features it observed")
            pose_id = poses[-1].id
        elif not any(p.id == pose_id for p in poses):
            raise unknown_name("pose of the current level", pose_id, (p.id for p in poses))
        inspection.interim.append(PoseFeaturePair(pose_id, z))

    def close_level(self, close_ring: bool = True) -> LevelSummary:
        """End the current level: link its last pose back to it and apply eq (10).

        The kept features are named (see :mod:`naming`), attached to the Feature graph of
        their best pose and merged into the unified graph. ``close_ring=False`` leaves out the
        edge from the last pose back to the level, for a caller that knows the robot cannot
        drive it straight (the edge is a straight segment the robot never drove).
        """
        inspection = self._require_inspection()
        level = inspection.level
        if level.closed:
            return LevelSummary(level.id, 0, ())
        poses = level.poses
        if close_ring:
            self.close_ring(level)
        kept = optimise_features(inspection.interim, self.params.d_check_F)
        pose_order = {p.id: p.index for p in poses}
        kept.sort(key=lambda f: pose_order[f.pose_id])  # stable: ties keep registration order
        names: list[str] = []
        ordinals: dict[str, int] = {}
        for feature in kept:
            z = feature.observation
            ordinals[z.label] = ordinals.get(z.label, 0) + 1
            names.append(self._add_feature(level, feature.pose_id, z, ordinals[z.label]).id)
        summary = LevelSummary(level.id, len(inspection.interim), tuple(names))
        inspection.interim = []
        level.closed = True
        self.revision += 1
        return summary

    def _add_feature(
        self, level: LevelNode, pose_id: str, z: Observation, ordinal: int
    ) -> FeatureNode:
        name = naming.feature_name(z.label, ordinal)
        feature = FeatureNode(
            id=naming.join(level.id, name),
            name=name,
            label=z.label,
            pose_id=pose_id,
            position=z.position.copy(),
            score=z.score,
            mask_area=z.mask_area,
            image=z.image,
        )
        return self.add_feature(feature)

    def finish_inspection(self, polygon_level: int = 0, every_level: bool = False) -> TargetNode:
        """Close the last level, build the containment polygon and mark the target inspected.

        The polygon's vertices are the pose nodes of the first level (000 Sec V-B), or of level
        ``polygon_level`` when the caller knows the first level's ring did not close; the target's
        position moves to the polygon's centroid (height unchanged). With fewer than three
        distinct poses there is no polygon and the position is left as detected. Detected
        targets that the polygon now contains, or that lie within ``d_check^T`` of the refined
        position, are re-detections of this target and are removed (000 Fig 17f);
        :attr:`pruned` lists them.

        With ``every_level`` the polygon grows with what was seen: it is the convex hull of every
        level's poses. A structure much larger than the camera's footprint may be circled only
        in part at some level, and one level's ring then covers only part of it.
        """
        inspection = self._require_inspection()
        self.close_level()
        target = inspection.target
        levels = target.levels
        if not 0 <= polygon_level < len(levels):
            raise InvalidInputError(f"{target.id} has no level {polygon_level}")
        if every_level:
            polygon = hull_polygon([p.position[:2] for level in levels for p in level.poses])
        else:
            polygon = ring_polygon([p.position[:2] for p in levels[polygon_level].poses])
        if polygon is not None:
            target.polygon = polygon
            centre = polygon_centroid(polygon)
            target.position = np.array([centre[0], centre[1], target.position[2]])
        target.status = TargetStatus.INSPECTED
        self._inspection = None
        self.pruned = self._prune_covered(target)
        self.revision += 1
        return target

    def _prune_covered(self, target: TargetNode) -> tuple[str, ...]:
        others = self.targets(TargetStatus.DETECTED)
        if not others:
            return ()
        # One vectorised test over every detected target: a mission keeps few, but a graph
        # built offline may hold thousands, and a test per target made that quadratic.
        positions = np.array([other.position for other in others])
        hits = np.linalg.norm(positions - target.position, axis=1) <= self.params.d_check_T
        if target.polygon is not None:
            hits |= polygon_contains(target.polygon, positions[:, :2])
        covered = tuple(other.id for other, hit in zip(others, hits, strict=True) if hit)
        for target_id in covered:
            self.discard_target(target_id)
        return covered

    def abort_inspection(self) -> TargetNode | None:
        """End an inspection cut short: finish it with what was gathered when its first level
        has enough poses for a containment polygon, otherwise cancel it."""
        if self._inspection is None:
            return None
        first = self.entry_level(self._inspection.target)
        if ring_polygon([p.position[:2] for p in first.poses]) is None:
            self.cancel_inspection()
            return None
        return self.finish_inspection()

    def cancel_inspection(self) -> TargetNode:
        """Undo the inspection in progress: its levels, poses and features leave the graph and
        the target is a detected one again."""
        inspection = self._require_inspection()
        target = inspection.target
        assert target.level_graph is not None
        removed = {target.id: False}
        for level in target.levels:
            removed[level.id] = True
            for pose in level.poses:
                removed[pose.id] = True
                removed.update((f.id, True) for f in pose.features)
        for key in [k for k in self._edges if removed.get(k[0]) or removed.get(k[1])]:
            del self._edges[key]
        for node_id, gone in removed.items():
            if gone:
                del self._nodes[node_id]
        target.level_graph = None
        self._inspection = None
        self.revision += 1
        return target

    def _require_inspection(self) -> _Inspection:
        if self._inspection is None:
            raise InvalidInputError("no inspection in progress; call begin_inspection first")
        return self._inspection

    # ------------------------------------------------------------------ building from nodes
    # The registration operators build through these, and so does the file loader: one way to
    # put a node into its local graph and the unified graph, with the edges its layer implies.
    def add_target(self, target: TargetNode) -> TargetNode:
        """Insert a target node into the Target layer, joined to the robot."""
        self._add_to(self.target_graph, target)
        self._connect(self.target_graph, self.robot, target, EdgeKind.SYMBOLIC)
        return target

    def add_level(self, level: LevelNode, via: ArrayLike | None = None) -> LevelNode:
        """Insert a level after the last level of its target (``level.target_id``), joined to
        the target and, through ``via`` (M x 3), to the previous level."""
        target = self._node_of(level.target_id, TargetNode)
        if target.level_graph is None:
            target.level_graph = LocalGraph(Layer.LEVEL, target)
        previous = target.levels[-1] if target.levels else None
        self._add_to(target.level_graph, level)
        self._connect(target.level_graph, target, level, EdgeKind.SYMBOLIC)
        if previous is not None:
            self._link(target.level_graph, previous, level, via)
        elif via is not None:
            raise InvalidInputError(f"{level.id} is the first level; it has no edge to realise")
        return level

    def add_pose(self, pose: PoseNode) -> PoseNode:
        """Insert a view pose after the last pose of its level (``pose.level_id``), chained to
        that pose, or to the level for its first pose."""
        level = self._node_of(pose.level_id, LevelNode)
        poses = level.poses
        self._add_to(level.pose_graph, pose)
        self._connect(level.pose_graph, poses[-1] if poses else level, pose, EdgeKind.SPATIAL)
        return pose

    def close_ring(self, level: LevelNode) -> None:
        """The spatial edge from a level's last pose back to the level, when it has two or
        more poses."""
        poses = level.poses
        if len(poses) > 1:
            self._connect(level.pose_graph, poses[-1], level, EdgeKind.SPATIAL)

    def add_feature(self, feature: FeatureNode) -> FeatureNode:
        """Insert a feature into the Feature graph of the pose that observed it
        (``feature.pose_id``), joined to that pose."""
        pose = self._node_of(feature.pose_id, PoseNode)
        if pose.feature_graph is None:
            pose.feature_graph = LocalGraph(Layer.FEATURE, pose)
        self._add_to(pose.feature_graph, feature)
        self._connect(pose.feature_graph, pose, feature, EdgeKind.SYMBOLIC)
        return feature

    def _node_of(self, node_id: str, kind: type[N]) -> N:
        node = self.node(node_id)
        if not isinstance(node, kind):
            raise InvalidInputError(f"{node_id!r} is not a {kind.__name__}")
        return node

    # ------------------------------------------------------------------ union
    def _add_to(self, local: LocalGraph, node: Node) -> None:
        """Register ``node`` in ``local`` and merge it into the unified graph (V and A union)."""
        if node.id in self._nodes and self._nodes[node.id] is not node:
            raise InvalidInputError(f"node id {node.id!r} already exists")
        local.nodes[node.id] = node
        self._nodes[node.id] = node

    def _link(
        self,
        local: LocalGraph,
        a: Node,
        b: Node,
        via: ArrayLike | None,
        ends: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> Edge:
        """A spatial edge realised by the polyline ``ends[0]``, ``via``, ``ends[1]`` (the two
        nodes' positions by default), weighing its length: the Euclidean distance when there is
        no ``via``. ``via`` is stored oriented along the edge's canonical key."""
        start, end = ends if ends is not None else (a.position, b.position)
        inner = (
            np.empty((0, 3)) if via is None else np.asarray(via, dtype=np.float64).reshape(-1, 3)
        )
        if not np.all(np.isfinite(inner)):
            raise InvalidInputError("via points must be finite")
        if a.id > b.id:  # orient along the canonical key, so the sum is reproducible
            a, b, start, end, inner = b, a, end, start, inner[::-1]
        polyline = np.vstack([start, inner, end])
        weight = float(np.linalg.norm(np.diff(polyline, axis=0), axis=1).sum())
        return self._connect(
            local, a, b, EdgeKind.SPATIAL, weight=weight, via=inner if len(inner) else None
        )

    def _connect(
        self,
        local: LocalGraph,
        a: Node,
        b: Node,
        kind: EdgeKind,
        *,
        weight: float | None = None,
        via: NDArray[np.float64] | None = None,
    ) -> Edge:
        """Register an edge in ``local`` and merge it into the unified graph (E union)."""
        if weight is None:
            weight = (
                float(np.linalg.norm(a.position - b.position)) if kind is EdgeKind.SPATIAL else 0.0
            )
        u, v = (a.id, b.id) if a.id <= b.id else (b.id, a.id)
        edge = Edge(u, v, kind, weight, via)
        local.edges[edge.key] = edge
        self._edges[edge.key] = edge
        return edge

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

        def summed(layer: Layer) -> LayerPopulation:
            counts = [g.population() for g in self.local_graphs(layer)]
            return LayerPopulation(sum(c[0] for c in counts), sum(c[1] for c in counts))

        targets = self.targets()
        return PopulationStats(
            target=summed(Layer.TARGET),
            level=summed(Layer.LEVEL),
            pose=summed(Layer.POSE),
            feature=summed(Layer.FEATURE),
            unified=LayerPopulation(len(self._nodes), len(self._edges)),
            targets_detected=len(targets),
            targets_inspected=sum(1 for t in targets if t.inspected),
        )
