"""002 eqs (1)-(2) checked by hand and by circling a box."""

import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.validation import build
from seminspect.planning.view_planner import (
    ViewConstraints,
    nearest_surface_point,
    next_view_pose,
)

WALL = np.array([[5.0, y, z] for y in np.linspace(-10, 10, 201) for z in (0.0, 1.0, 2.0)])


def test_steps_by_hand_in_front_of_a_wall() -> None:
    c = ViewConstraints(d_view=2.0, overlap_h=0.6, hfov_deg=90.0)
    pose = next_view_pose([0, 0, 1], WALL, c)
    # d = 5, d_insp = 3 towards the wall; d_hov = 2 tan(45 deg) * 2 * 0.4 = 1.6 to the left
    np.testing.assert_allclose(pose.position, [3.0, 1.6, 1.0], atol=1e-9)
    assert pose.distance == pytest.approx(5.0)
    assert pose.yaw == pytest.approx(0.0)  # eq (2): facing the wall from the new pose
    right = next_view_pose([0, 0, 1], WALL, c.model_copy(update={"direction": -1}))
    np.testing.assert_allclose(right.position, [3.0, -1.6, 1.0], atol=1e-9)


def test_climbing_a_level_moves_up_by_the_vertical_step() -> None:
    c = ViewConstraints(d_view=2.0, overlap_v=0.5, vfov_deg=90.0)
    pose = next_view_pose([3, 0, 1], WALL, c, climb=True)
    np.testing.assert_allclose(pose.position, [3.0, 0.0, 1.0 + 2.0], atol=1e-9)
    assert c.vertical_step == pytest.approx(2.0)


def test_recursion_circles_an_object_at_the_viewing_distance() -> None:
    angles = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    box = np.array([[1.5 * np.cos(a), 1.0 * np.sin(a), 0.5] for a in angles])
    c = ViewConstraints(d_view=2.5)
    path, here = [], np.array([-4.0, 0.0, 0.5])
    for _ in range(40):  # eq (1) applied from each pose, as an inspection flies on
        path.append(next_view_pose(here, box, c))
        here = path[-1].position
    distances = np.array([nearest_surface_point(p.position, box)[1] for p in path[1:]])
    assert np.all(np.abs(distances - 2.5) < 0.4)
    bearings = np.unwrap([math.atan2(p.position[1], p.position[0]) for p in path])
    assert bearings[-1] - bearings[0] < -2 * np.pi  # more than a full clockwise turn
    for p in path:  # every pose looks at the object
        towards = math.atan2(-p.position[1], -p.position[0])
        assert abs(math.remainder(p.yaw - towards, math.tau)) < 0.6


def test_bad_inputs() -> None:
    with pytest.raises(InvalidInputError, match="direction"):
        build(ViewConstraints, {"direction": 0})
    with pytest.raises(InvalidInputError):
        next_view_pose([0, 0, 0], np.empty((0, 3)), ViewConstraints())
    with pytest.raises(PlanningError, match="on the surface"):
        next_view_pose([5, 0, 1], WALL, ViewConstraints())
