"""The registration operators' pieces, checked on their own (000 eqs (4), (7), (9), (10))."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.graphs.lsg.model import Layer, LevelNode, LocalGraph, TargetNode
from seminspect.graphs.lsg.optimisation import PoseFeaturePair
from seminspect.graphs.lsg.registration import (
    Inspection,
    covered_targets,
    enclose_target,
    kept_features,
    merge_detection,
    new_level,
    new_pose,
    new_target,
)
from seminspect.perception.observation import Observation


def target_with_ring(ring: list[tuple[float, float]]) -> tuple[TargetNode, LevelNode]:
    target = new_target(Observation([0.0, 0.0, 0.7], label="Car", mask_area=10), index=3)
    target.level_graph = LocalGraph(Layer.LEVEL, target)
    level = new_level(target, Observation.view_pose([-2.0, 0.0, 0.7]))
    target.level_graph.nodes[level.id] = level
    for x, y in ring:
        pose = new_pose(level, Observation.view_pose([x, y, 0.7]))
        level.pose_graph.nodes[pose.id] = pose
    return target, level


def test_new_nodes_are_named_by_the_numbering_rules() -> None:
    target, level = target_with_ring([(-2, 0), (0, 2)])
    assert (target.id, target.index) == ("car-3", 3)
    assert level.id == "car-3/Level-0" and level.target_id == target.id
    assert [p.id for p in level.poses] == ["car-3/Level-0/pose-0", "car-3/Level-0/pose-1"]


def test_a_larger_mask_sets_the_attributes_of_a_duplicate() -> None:
    target = new_target(Observation([0.0, 0.0, 0.7], label="car", mask_area=10), index=0)
    merge_detection(target, Observation([1.0, 0.0, 0.7], label="car", mask_area=5))
    assert target.observations == 2 and target.position[0] == 0.0
    merge_detection(target, Observation([2.0, 0.0, 0.7], label="car", mask_area=50))
    assert target.observations == 3 and target.position[0] == 2.0 and target.mask_area == 50


def test_kept_features_are_numbered_per_label_in_pose_order() -> None:
    _, level = target_with_ring([(-2, 0), (0, 2)])
    first, second = (p.id for p in level.poses)
    interim = [
        PoseFeaturePair(second, Observation([0.0, 1.0, 0.7], label="hood", score=0.9)),
        PoseFeaturePair(first, Observation([0.0, 5.0, 0.7], label="hood", score=0.5)),
        PoseFeaturePair(first, Observation([0.1, 1.0, 0.7], label="hood", score=0.4)),
    ]
    features = kept_features(level, interim, d_check_F=0.5)
    assert [(f.name, f.pose_id) for f in features] == [("hood-1", first), ("hood-2", second)]


def test_an_inspection_pairs_features_with_a_pose_of_its_level() -> None:
    target, level = target_with_ring([])
    inspection = Inspection(target, level)
    hood = Observation([0.0, 1.0, 0.7], label="hood")
    with pytest.raises(InvalidInputError, match="register a pose"):
        inspection.observe_feature(hood, None)
    pose = new_pose(level, Observation.view_pose([-2.0, 0.0, 0.7]))
    level.pose_graph.nodes[pose.id] = pose
    inspection.observe_feature(hood, None)
    with pytest.raises(UnknownNameError):
        inspection.observe_feature(hood, "car-3/Level-0/pose-9")
    assert [pair.pose_id for pair in inspection.interim] == [pose.id]


def test_the_polygon_moves_the_target_and_covers_re_detections() -> None:
    target, _ = target_with_ring([(-2, 0), (0, 2), (2, 0), (0, -2)])
    target.position = np.array([0.5, 0.5, 0.9])
    with pytest.raises(InvalidInputError, match="no level 1"):
        enclose_target(target, 1, every_level=False)
    enclose_target(target, 0, every_level=False)
    np.testing.assert_allclose(target.position, [0.0, 0.0, 0.9], atol=1e-12)
    inside = new_target(Observation([1.0, 0.5, 0.7], label="car"), index=4)
    near = new_target(Observation([2.5, 0.0, 0.7], label="car"), index=5)
    far = new_target(Observation([9.0, 0.0, 0.7], label="car"), index=6)
    assert covered_targets(target, [inside, near, far], d_check_T=2.6) == ("car-4", "car-5")
    assert covered_targets(target, [], d_check_T=2.6) == ()


def test_too_few_poses_leave_the_target_where_it_was_detected() -> None:
    target, _ = target_with_ring([(-2, 0), (0, 2)])
    enclose_target(target, 0, every_level=True)
    assert target.polygon is None and target.position[0] == 0.0
