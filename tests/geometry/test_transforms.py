import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import (
    as_point,
    as_points,
    as_quaternion,
    bearing_offset,
    quat_from_yaw,
    wrap_angle,
    yaw_from_quat,
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
