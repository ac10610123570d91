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

What each operator makes of an observation is in :mod:`.registration`, the union in
:mod:`.union`, and the Table 3 statistics in :mod:`.population`. The structure the operators
build, and the ways to walk it, are in :mod:`.structure`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from numpy.typing import ArrayLike

from seminspect.core.errors import InvalidInputError
from seminspect.core.params import PRESETS, InspectionParams
from seminspect.geometry.polygons import ring_polygon
from seminspect.geometry.transforms import IDENTITY_QUAT, as_point, as_quaternion, yaw_from_quat
from seminspect.graphs.lsg import naming
from seminspect.graphs.lsg.claims import TargetClaims
from seminspect.graphs.lsg.model import (
    Edge,
    Layer,
    LevelNode,
    LocalGraph,
    Node,
    PoseNode,
    TargetNode,
    TargetStatus,
)
from seminspect.graphs.lsg.optimisation import (
    ExistingTarget,
    InspectedView,
    Outcome,
    optimise_targets,
)
from seminspect.graphs.lsg.registration import (
    Inspection,
    LevelSummary,
    TargetUpdate,
    covered_targets,
    enclose_target,
    kept_features,
    merge_detection,
    new_level,
    new_pose,
    new_target,
)
from seminspect.graphs.lsg.structure import GraphStructure
from seminspect.perception.observation import Observation


class LayeredSemanticGraph(GraphStructure):
    """A 3D Layered Semantic Graph, built incrementally from observations.

    How to walk one (``targets()``, ``target.levels``, ``level.poses`` ...) is inherited from
    :class:`~.structure.GraphStructure`.

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
        super().__init__(robot_position, robot_orientation)
        self.params = params if params is not None else PRESETS["urban-simulated"]
        self._pending: list[Observation] = []
        self._inspection: Inspection | None = None
        #: Detected targets removed by the last :meth:`finish_inspection`.
        self.pruned: tuple[str, ...] = ()
        self.next_target_index = 0
        #: Incremented on every change; planners use it to invalidate their caches.
        self.revision = 0
        #: Which robot has taken which target, when several robots share this graph.
        self.claims = TargetClaims()

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
                target = self.unified.nodes[into]  # type: ignore[index]
                assert isinstance(target, TargetNode)
                merge_detection(target, candidates[i])
                resolved[i] = into
        if candidates:
            self.revision += 1
        return TargetUpdate(tuple(decisions), tuple(resolved))

    def _add_target(self, z: Observation) -> TargetNode:
        index = self.next_target_index
        self.next_target_index += 1
        return self.add_target(new_target(z, index))

    def discard_target(self, target_id: str) -> TargetNode:
        """Remove a detected (uninspected) target found to be invalid, e.g. a false detection
        that is not there when the robot comes to look; Φ's removal of invalid nodes (eq 4)."""
        target = self.target(target_id)
        if target.inspected or target is self.inspecting:
            raise InvalidInputError(
                f"{target.id} is inspected; only detected targets are discarded"
            )
        self.unified.discard(self.target_graph, target.id)
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
        edge = self.unified.link(self.target_graph, first, second, via, ends)
        self.revision += 1
        return edge

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
        self._inspection = Inspection(target, level)
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
        level = self.add_level(new_level(target, z), via)
        self.revision += 1
        return level

    def register_pose(self, z: Observation) -> PoseNode:
        """R of eq (9): a tracked view pose, chained to the previous one (or to its level)."""
        level = self._require_inspection().level
        if level.closed:
            raise InvalidInputError(f"{level.id} is closed")
        pose = self.add_pose(new_pose(level, z))
        self.revision += 1
        return pose

    def register_feature(self, z: Observation, pose_id: str | None = None) -> None:
        """Add a feature observation to the interim ``G~^PF`` of the current level.

        ``pose_id`` defaults to the latest pose of the level.
        """
        inspection = self._require_inspection()
        naming.check_label(z.label)
        inspection.observe_feature(z, pose_id)

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
        if close_ring:
            self.close_ring(level)
        features = kept_features(level, inspection.interim, self.params.d_check_F)
        names = tuple(self.add_feature(feature).id for feature in features)
        summary = LevelSummary(level.id, len(inspection.interim), names)
        inspection.interim = []
        level.closed = True
        self.revision += 1
        return summary

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
        enclose_target(target, polygon_level, every_level)
        target.status = TargetStatus.INSPECTED
        self._inspection = None
        self.pruned = self._prune_covered(target)
        self.revision += 1
        return target

    def _prune_covered(self, target: TargetNode) -> tuple[str, ...]:
        covered = covered_targets(
            target, self.targets(TargetStatus.DETECTED), self.params.d_check_T
        )
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
        poses = [pose for level in target.levels for pose in level.poses]
        gone: list[Node] = [*target.levels, *poses, *(f for p in poses for f in p.features)]
        self.unified.remove(node.id for node in gone)
        target.level_graph = None
        self._inspection = None
        self.revision += 1
        return target

    def _require_inspection(self) -> Inspection:
        if self._inspection is None:
            raise InvalidInputError("no inspection in progress; call begin_inspection first")
        return self._inspection
