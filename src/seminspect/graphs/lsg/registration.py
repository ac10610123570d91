"""What the registration operators R of 000 Sec V make of observations.

The node each observation becomes (named by :mod:`naming`), how a duplicate detection updates
the target it merged into (eq (4)), which features a closed level keeps and in what order
(eq (10)), and the containment polygon and pruning that end an inspection (Sec V-B).
:class:`~seminspect.graphs.lsg.graph.LayeredSemanticGraph` applies them to its layers; they
hold no graph state, so each can be checked on its own.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.geometry.polygons import (
    hull_polygon,
    polygon_centroid,
    polygon_contains,
    ring_polygon,
)
from seminspect.graphs.lsg import naming
from seminspect.graphs.lsg.model import FeatureNode, LevelNode, PoseNode, TargetNode
from seminspect.graphs.lsg.optimisation import (
    Outcome,
    PoseFeaturePair,
    TargetDecision,
    optimise_features,
)
from seminspect.perception.observation import Observation


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
class Inspection:
    """The inspection in progress: its target, current level and interim ``G~^PF``."""

    target: TargetNode
    level: LevelNode
    interim: list[PoseFeaturePair] = field(default_factory=list)

    def observe_feature(self, z: Observation, pose_id: str | None) -> None:
        """Add a (pose, feature) pair to ``G~^PF``; ``pose_id`` defaults to the latest pose."""
        poses = self.level.poses
        if pose_id is None:
            if not poses:
                raise InvalidInputError("register a pose before the features it observed")
            pose_id = poses[-1].id
        elif not any(p.id == pose_id for p in poses):
            raise unknown_name("pose of the current level", pose_id, (p.id for p in poses))
        self.interim.append(PoseFeaturePair(pose_id, z))


def new_target(z: Observation, index: int) -> TargetNode:
    """The detected target a detection becomes, numbered ``index`` (see :mod:`naming`)."""
    return TargetNode(
        id=naming.target_name(z.label, index),
        label=z.label,
        index=index,
        position=z.position.copy(),
        score=z.score,
        mask_area=z.mask_area,
        image=z.image,
        stamp=z.stamp,
    )


def merge_detection(target: TargetNode, z: Observation) -> None:
    """A duplicate detection: the larger mask (closer, fuller view) sets the attributes."""
    target.observations += 1
    if z.mask_area > target.mask_area and not target.inspected:
        target.position = z.position.copy()
        target.score = z.score
        target.mask_area = z.mask_area
        target.image = z.image
        target.stamp = z.stamp


def new_level(target: TargetNode, z: Observation) -> LevelNode:
    """The next level of ``target`` (eq (7)), starting where ``z`` was taken."""
    index = len(target.levels)
    return LevelNode(
        id=naming.join(target.id, naming.level_name(index)),
        name=naming.level_name(index),
        index=index,
        target_id=target.id,
        position=z.position.copy(),
        stamp=z.stamp,
    )


def new_pose(level: LevelNode, z: Observation) -> PoseNode:
    """The next view pose of ``level`` (eq (9)), tracked at ``z``."""
    index = len(level.poses)
    return PoseNode(
        id=naming.join(level.id, naming.pose_name(index)),
        name=naming.pose_name(index),
        index=index,
        level_id=level.id,
        position=z.position.copy(),
        orientation=z.orientation.copy(),
        image=z.image,
        stamp=z.stamp,
    )


def kept_features(
    level: LevelNode, interim: Sequence[PoseFeaturePair], d_check_F: float
) -> list[FeatureNode]:
    """Eq (10) over the level's ``G~^PF``: the features it keeps, named one-based per label in
    the order of the pose that observed them best."""
    kept = optimise_features(interim, d_check_F)
    pose_order = {p.id: p.index for p in level.poses}
    kept.sort(key=lambda f: pose_order[f.pose_id])  # stable: ties keep registration order
    features: list[FeatureNode] = []
    ordinals: dict[str, int] = {}
    for pruned in kept:
        z = pruned.observation
        ordinals[z.label] = ordinals.get(z.label, 0) + 1
        name = naming.feature_name(z.label, ordinals[z.label])
        features.append(
            FeatureNode(
                id=naming.join(level.id, name),
                name=name,
                label=z.label,
                pose_id=pruned.pose_id,
                position=z.position.copy(),
                score=z.score,
                mask_area=z.mask_area,
                image=z.image,
            )
        )
    return features


def enclose_target(target: TargetNode, polygon_level: int, every_level: bool) -> None:
    """Give ``target`` its containment polygon and move it to the polygon's centroid (height
    unchanged); with fewer than three distinct poses there is no polygon and it stays put.

    The vertices are the poses of level ``polygon_level`` (000 Sec V-B uses the first), or with
    ``every_level`` the convex hull of every level's poses.
    """
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


def covered_targets(
    target: TargetNode, others: Sequence[TargetNode], d_check_T: float
) -> tuple[str, ...]:
    """The detected targets that re-detect an inspected one (000 Fig 17f): inside its
    containment polygon or within ``d_check^T`` of its refined position."""
    if not others:
        return ()
    # One vectorised test over every detected target: a mission keeps few, but a graph
    # built offline may hold thousands, and a test per target made that quadratic.
    positions: NDArray[np.float64] = np.array([other.position for other in others])
    hits = np.linalg.norm(positions - target.position, axis=1) <= d_check_T
    if target.polygon is not None:
        hits |= polygon_contains(target.polygon, positions[:, :2])
    return tuple(other.id for other, hit in zip(others, hits, strict=True) if hit)
