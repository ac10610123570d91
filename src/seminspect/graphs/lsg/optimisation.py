"""The two graph optimisations Φ of 000 Sec V: the Target layer (eq 4) and the Pose-Feature
graph (eq 10). Both are pure functions over plain data so they can be checked by hand."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from seminspect.geometry.polygons import polygon_contains, polygon_meets_sector
from seminspect.geometry.spatial_hash import PointHash
from seminspect.geometry.transforms import bearing_offset
from seminspect.perception.observation import Observation


class Outcome(str, Enum):
    """What eq (4) decided for one registered detection."""

    ADDED = "added"  # a new, unique detected target v_D
    MERGED = "merged"  # within d_check^T of an existing v_D: a duplicate of it
    INSIDE_POLYGON = "inside-polygon"  # P(v_D, v_I) = 1 for an inspected target in view
    NEAR_INSPECTED = "near-inspected"  # within d_check^T of an inspected target


@dataclass(frozen=True, slots=True)
class InspectedView:
    """What eq (4) needs of an inspected target: position and containment polygon."""

    target_id: str
    position: NDArray[np.float64]
    polygon: NDArray[np.float64] | None


@dataclass(frozen=True, slots=True)
class ExistingTarget:
    """A detected, uninspected target already in the graph."""

    target_id: str
    position: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class TargetDecision:
    """Eq (4)'s verdict on candidate ``candidate`` (index into the registered list)."""

    candidate: int
    outcome: Outcome
    #: The node the candidate merged into, or the inspected target that rejected it.
    target_id: str | None = None
    #: For a duplicate of a candidate added earlier in the same call: that candidate's index.
    into_candidate: int | None = None


def inspected_in_view(
    inspected: Sequence[InspectedView],
    *,
    robot_position: NDArray[np.float64],
    robot_yaw: float,
    d_max: float,
    fov_rad: float,
) -> list[InspectedView]:
    """``V_I,wsr`` of eq (4): inspected targets within ``d_max`` of the robot and inside the FOV.

    The paper writes ``θ_vI <= α`` with α the full field of view; the viewing angle is measured
    from the optical axis here, so a point is in view when ``|θ| <= α / 2``. An inspected
    target is in view when its centre or any vertex of its containment polygon is: seen from
    close by, an 8 m truck can fill one side of the image while its centre lies outside it.
    It is also in view when its polygon overlaps the field of view out to ``d_max``: a robot
    beside (or above) a building 40 m long can face its wall with every vertex and the centre
    out of the image, and the centre farther than ``d_max``.
    """
    half_fov = 0.5 * fov_rad

    def centre_or_vertex_in_view(view: InspectedView) -> bool:
        if np.linalg.norm(view.position - robot_position) > d_max:
            return False
        points = [view.position[:2]] + ([] if view.polygon is None else list(view.polygon))
        return any(bearing_offset(robot_position, robot_yaw, p) <= half_fov for p in points)

    def polygon_in_view(view: InspectedView) -> bool:
        return view.polygon is not None and polygon_meets_sector(
            view.polygon, robot_position, robot_yaw, half_fov, d_max
        )

    return [v for v in inspected if centre_or_vertex_in_view(v) or polygon_in_view(v)]


def optimise_targets(
    candidates: Sequence[Observation],
    existing: Sequence[ExistingTarget],
    inspected: Sequence[InspectedView],
    *,
    robot_position: NDArray[np.float64],
    robot_yaw: float,
    d_check_T: float,
    d_max: float,
    fov_rad: float,
    reject_near_inspected: bool = True,
) -> list[TargetDecision]:
    """Φ of 000 eq (4) on the unoptimised Target graph.

    Candidates are visited largest mask first (the closest, most complete view of an object
    claims the node; ties keep registration order). Each one is

    1. rejected when it falls inside the containment polygon of an inspected target of
       ``V_I,wsr`` (``P(v_D, v_I) = 0`` must hold);
    2. rejected when it lies within ``d_check^T`` of an inspected target (an extension: eq (4)
       checks uniqueness among ``V_D`` only, which lets a re-detection of an inspected target
       whose centre is just outside the field of view become a new target);
    3. merged into the nearest detected target within ``d_check^T`` (``D(p_i, p_j) > d_check^T``
       must hold between detected targets), or into a candidate accepted earlier in this call;
    4. otherwise added as a new detected target.

    Returns one decision per candidate, in candidate order; the caller names added nodes.
    """
    in_view = inspected_in_view(
        inspected, robot_position=robot_position, robot_yaw=robot_yaw, d_max=d_max, fov_rad=fov_rad
    )
    near_inspected: PointHash[str] = PointHash(d_check_T)
    if reject_near_inspected:
        for view in inspected:
            near_inspected.add(view.position, view.target_id)
    kept: PointHash[tuple[str, int | None]] = PointHash(d_check_T)
    for target in existing:
        kept.add(target.position, (target.target_id, None))
    decisions: dict[int, TargetDecision] = {}
    for i in sorted(range(len(candidates)), key=lambda i: (-candidates[i].mask_area, i)):
        point = candidates[i].position
        decision = _rejection(i, point, in_view, near_inspected, d_check_T)
        if decision is None:
            duplicate = kept.nearest_within(point, d_check_T)
            if duplicate is None:
                decision = TargetDecision(i, Outcome.ADDED)
                kept.add(point, ("", i))
            else:
                (target_id, from_candidate), _ = duplicate
                decision = TargetDecision(
                    i, Outcome.MERGED, target_id or None, into_candidate=from_candidate
                )
        decisions[i] = decision
    return [decisions[i] for i in range(len(candidates))]


def _rejection(
    i: int,
    point: NDArray[np.float64],
    in_view: Sequence[InspectedView],
    near_inspected: PointHash[str],
    d_check_T: float,
) -> TargetDecision | None:
    """The polygon test of eq (4), then the distance to inspected targets."""
    for view in in_view:
        if view.polygon is not None and polygon_contains(view.polygon, point[:2])[0]:
            return TargetDecision(i, Outcome.INSIDE_POLYGON, view.target_id)
    near = near_inspected.nearest_within(point, d_check_T)
    if near is not None:
        return TargetDecision(i, Outcome.NEAR_INSPECTED, near[0])
    return None


@dataclass(frozen=True, slots=True)
class PoseFeaturePair:
    """A node of the interim graph ``G~^PF``: a feature observation and the pose that saw it."""

    pose_id: str
    observation: Observation


@dataclass(frozen=True, slots=True)
class PrunedFeature:
    """A feature kept by eq (10), with the pose of highest confidence and its merged count."""

    pose_id: str
    observation: Observation
    merged: int


def optimise_features(pairs: Sequence[PoseFeaturePair], d_check_F: float) -> list[PrunedFeature]:
    """Φ of 000 eq (10): prune the interim Pose-Feature graph at the end of a level.

    Observations of the same label closer than ``d_check^F`` are one feature. Each feature keeps
    the observing pose of highest confidence ``c(v^P, v^F)`` and that observation's attributes.
    Greedy in descending confidence (ties: registration order), which guarantees that kept
    features of a label are pairwise farther apart than ``d_check^F``.

    The paper states the distance constraint over all features; it is applied per label here,
    because distinct parts of one vehicle (a front light and the front bumper, say) lie closer
    than the paper's 1.5 m and would otherwise collapse into one feature.
    """
    kept: list[PrunedFeature] = []
    by_label: dict[str, list[int]] = {}
    for index, pair in enumerate(pairs):
        by_label.setdefault(pair.observation.label, []).append(index)
    for indices in by_label.values():
        ranked = sorted(indices, key=lambda k: (-pairs[k].observation.score, k))
        absorbed = np.zeros(len(pairs), dtype=bool)
        for k in ranked:
            if absorbed[k]:
                continue
            centre = pairs[k].observation.position
            members = [
                m
                for m in ranked
                if not absorbed[m] and _distance(pairs[m].observation.position, centre) <= d_check_F
            ]
            absorbed[members] = True
            kept.append(PrunedFeature(pairs[k].pose_id, pairs[k].observation, len(members)))
    order = {id(pair.observation): n for n, pair in enumerate(pairs)}
    kept.sort(key=lambda f: order[id(f.observation)])
    return kept


def _distance(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    return math.dist(a, b)
