import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import (
    as_point,
    as_points,
    as_quaternion,
    bearing_offset,
    body_from_world,
    matrix_from_euler_xyz,
    quat_from_yaw,
    quat_from_yaw_pitch,
    reframe_points,
    rotate_xy,
    world_from_body,
    wrap_angle,
    yaw_from_quat,
    yaw_rotation,
)


@given(st.floats(-10 * math.pi, 10 * math.pi))
def test_yaw_survives_a_quaternion_round_trip(yaw: float) -> None:
    assert math.isclose(math.cos(yaw_from_quat(quat_from_yaw(yaw)) - yaw), 1.0, abs_tol=1e-9)
    assert -math.pi < wrap_angle(yaw) <= math.pi


def test_bearing_offset_measures_from_the_heading() -> None:
    assert bearing_offset([0, 0, 0], 0.0, [10, 0, 0]) == pytest.approx(0.0)
    assert bearing_offset([0, 0, 0], 0.0, [0, 10, 0]) == pytest.approx(math.pi / 2)
    assert bearing_offset([0, 0, 0], math.pi, [10, 0.1, 0]) == pytest.approx(
        math.pi - 0.01, abs=1e-4
    )


@pytest.mark.parametrize("bad", [[1, 2], [1, 2, float("nan")], "abc", [1, 2, float("inf")]])
def test_bad_points_are_refused(bad) -> None:
    with pytest.raises(InvalidInputError):
        as_point(bad)


def test_bad_clouds_and_quaternions_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="empty"):
        as_points(np.empty((0, 3)))
    with pytest.raises(InvalidInputError, match="NaN"):
        as_points([[0, 0, float("nan")]])
    with pytest.raises(InvalidInputError, match="zero quaternion"):
        as_quaternion([0, 0, 0, 0])
    np.testing.assert_allclose(as_quaternion([0, 0, 0, 2]), [0, 0, 0, 1])


def test_a_quarter_turn_takes_forward_to_left():
    x, y = rotate_xy(math.cos(math.pi / 2), math.sin(math.pi / 2), 1.0, 0.0)
    assert x == pytest.approx(0.0, abs=1e-15) and y == pytest.approx(1.0)
    forward = np.array([[1.0, 0.0, 0.5]])
    np.testing.assert_allclose(
        world_from_body(forward, np.array([math.pi / 2])), [[0, 1, 0.5]], atol=1e-15
    )


def test_body_from_world_undoes_world_from_body():
    rng = np.random.default_rng(0)
    vectors, yaw = rng.normal(size=(50, 3)), rng.uniform(-4, 4, 50)
    np.testing.assert_allclose(body_from_world(world_from_body(vectors, yaw), yaw), vectors)
    rotation = Rotation.from_euler("z", yaw[:, None])
    np.testing.assert_allclose(world_from_body(vectors, yaw), rotation.apply(vectors), atol=1e-12)


def test_reframe_points_carries_a_pose_onto_its_other_reading():
    odometry, truth = (np.array([1.0, 2.0, 0.0]), 0.3), (np.array([1.5, 1.0, 0.2]), -0.4)
    ahead = odometry[0] + np.array([math.cos(odometry[1]), math.sin(odometry[1]), 0.0])
    moved = reframe_points(ahead, *odometry, *truth)
    expected = truth[0] + np.array([math.cos(truth[1]), math.sin(truth[1]), 0.0])
    np.testing.assert_allclose(moved, expected)
    np.testing.assert_allclose(reframe_points(moved, *truth, *odometry), ahead)
    np.testing.assert_allclose(
        yaw_rotation(0.3).apply([1.0, 0, 0]), [math.cos(0.3), math.sin(0.3), 0]
    )


def test_a_camera_pitched_down_looks_below_the_horizon():
    np.testing.assert_allclose(quat_from_yaw_pitch(0.7, 0.0), quat_from_yaw(0.7), atol=1e-15)
    view = Rotation.from_quat(quat_from_yaw_pitch(0.0, 0.2)).apply([1.0, 0.0, 0.0])
    assert view[2] == pytest.approx(-math.sin(0.2))


def test_matrix_from_euler_xyz_is_scipys_to_rounding():
    angles = np.random.default_rng(1).uniform(-math.pi, math.pi, (20, 3))
    for a in angles:
        expected = Rotation.from_euler("xyz", a).as_matrix()
        np.testing.assert_allclose(matrix_from_euler_xyz(a), expected, atol=1e-14)
