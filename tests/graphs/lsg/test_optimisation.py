"""Hand-computed cases for Φ of 000 eq (4) and eq (10)."""

import math

import numpy as np
import pytest

from seminspect.graphs.lsg.optimisation import (
    ExistingTarget,
    InspectedView,
    Outcome,
    PoseFeaturePair,
    inspected_in_view,
    optimise_features,
    optimise_targets,
)
from seminspect.perception.observation import Observation

FOV = math.radians(69.4)
ORIGIN = np.zeros(3)
#: An inspected target at x=10 whose containment polygon is the square 8..12 x -2..2.
INSPECTED = InspectedView(
    "car-0", np.array([10.0, 0.0, 0.0]), np.array([[8, -2], [12, -2], [12, 2], [8, 2.0]])
)


def detection(x: float, y: float, area: float = 1000.0, label: str = "car") -> Observation:
    return Observation([x, y, 0.0], label=label, score=0.9, mask_area=area)


def run(candidates, existing=(), inspected=(), yaw=0.0, near=True):
    return optimise_targets(
        candidates,
        list(existing),
        list(inspected),
        robot_position=ORIGIN,
        robot_yaw=yaw,
        d_check_T=4.0,
        d_max=30.0,
        fov_rad=FOV,
        reject_near_inspected=near,
    )


def test_two_detections_within_d_check_are_one_target_the_larger_mask_wins() -> None:
    decisions = run([detection(20, 0, area=500), detection(23, 0, area=2000)])
    assert decisions[1].outcome is Outcome.ADDED
    assert decisions[0].outcome is Outcome.MERGED and decisions[0].into_candidate == 1


def test_uniqueness_radius_is_inclusive_at_d_check() -> None:
    existing = [ExistingTarget("truck-3", np.array([20.0, 0.0, 0.0]))]
    assert run([detection(24.0, 0)], existing)[0].target_id == "truck-3"
    assert run([detection(24.01, 0)], existing)[0].outcome is Outcome.ADDED


def test_detection_inside_a_polygon_in_view_is_rejected() -> None:
    decision = run([detection(9, 1)], inspected=[INSPECTED])[0]
    assert (decision.outcome, decision.target_id) == (Outcome.INSIDE_POLYGON, "car-0")


def test_polygon_of_a_target_behind_the_robot_is_not_checked() -> None:
    # Facing away: car-0 is not in V_I,wsr, so eq (4) alone would accept the detection ...
    assert (
        run([detection(9, 1)], inspected=[INSPECTED], yaw=math.pi, near=False)[0].outcome
        is Outcome.ADDED
    )
    # ... and the near-inspected extension rejects it (1.41 m from car-0).
    assert (
        run([detection(9, 1)], inspected=[INSPECTED], yaw=math.pi)[0].outcome
        is Outcome.NEAR_INSPECTED
    )


def test_a_long_target_is_in_view_when_part_of_its_polygon_is() -> None:
    truck = InspectedView(
        "truck-1", np.array([10.0, 8.0, 0.0]), np.array([[3, 6], [17, 6], [17, 10], [3, 10.0]])
    )  # centre 38.7 deg off axis; its near end inside the 34.7 deg half field of view
    views = inspected_in_view(
        [truck], robot_position=ORIGIN, robot_yaw=0.0, d_max=30.0, fov_rad=FOV
    )
    assert [v.target_id for v in views] == ["truck-1"]
    assert (
        run([detection(5, 8)], inspected=[truck], near=False)[0].outcome is Outcome.INSIDE_POLYGON
    )


#: A building 200 m long and 30 m deep, centred at (0, 17): corners far off to the sides.
LONG_BUILDING = InspectedView(
    "building-0",
    np.array([0.0, 17.0, 0.0]),
    np.array([[-100, 2], [100, 2], [100, 32], [-100, 32.0]]),
)


@pytest.mark.parametrize(
    ("robot", "yaw"),
    [((30.0, 0.0, 4.0), math.pi / 2), ((30.0, 15.0, 10.0), -math.pi / 2)],
    ids=["facing-its-wall", "above-it"],
)
def test_a_building_is_in_view_when_its_wall_fills_the_image(robot, yaw) -> None:
    """Centre and every corner out of view: the robot faces the building's wall from 2 m, or
    flies above it (inside its polygon) looking down its length."""

    def in_view(position, heading):
        return inspected_in_view(
            [LONG_BUILDING],
            robot_position=np.array(position),
            robot_yaw=heading,
            d_max=30.0,
            fov_rad=FOV,
        )

    assert [v.target_id for v in in_view(robot, yaw)] == ["building-0"]
    assert in_view((30.0, 0.0, 4.0), -math.pi / 2) == []  # outside it, facing away


def test_view_set_uses_range_and_half_fov() -> None:
    far = InspectedView("far", np.array([40.0, 0.0, 0.0]), None)
    side = InspectedView("side", np.array([10.0, 7.5, 0.0]), None)  # 36.9 deg off axis
    edge = InspectedView("edge", np.array([10.0, 6.5, 0.0]), None)  # 33.0 deg, inside 34.7
    views = inspected_in_view(
        [INSPECTED, far, side, edge], robot_position=ORIGIN, robot_yaw=0.0, d_max=30.0, fov_rad=FOV
    )
    assert [v.target_id for v in views] == ["car-0", "edge"]


def pair(pose: str, label: str, x: float, score: float) -> PoseFeaturePair:
    return PoseFeaturePair(pose, Observation([x, 0, 0], label=label, score=score, mask_area=100))


def test_features_merge_per_label_and_keep_the_most_confident_pose() -> None:
    pairs = [
        pair("pose-0", "hood", 0.0, 0.6),
        pair("pose-1", "hood", 1.0, 0.9),
        pair("pose-2", "hood", 5.0, 0.5),
        pair("pose-1", "front-bumper", 0.5, 0.7),
    ]
    kept = optimise_features(pairs, d_check_F=1.5)
    summary = [(f.pose_id, f.observation.label, f.observation.position[0], f.merged) for f in kept]
    assert summary == [
        ("pose-1", "hood", 1.0, 2),
        ("pose-2", "hood", 5.0, 1),
        ("pose-1", "front-bumper", 0.5, 1),
    ]


def test_kept_features_of_a_label_are_farther_apart_than_d_check() -> None:
    pairs = [pair("p", "door", x, s) for x, s in ((0.0, 0.9), (1.2, 0.8), (2.4, 0.7))]
    kept = optimise_features(pairs, d_check_F=1.5)
    assert [f.observation.position[0] for f in kept] == [0.0, 2.4]
    assert kept[0].merged == 2


def test_equal_confidence_keeps_the_earliest_observation() -> None:
    kept = optimise_features([pair("a", "hood", 0, 0.5), pair("b", "hood", 0.1, 0.5)], 1.5)
    assert [f.pose_id for f in kept] == ["a"]


@pytest.mark.parametrize("d", [0.5, 1.5, 3.0])
def test_empty_interim_graph_prunes_to_nothing(d) -> None:
    assert optimise_features([], d) == []
