import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.robot import Robot
from sim_worlds import box_world


@pytest.fixture(scope="module")
def world():
    """A crate at x 4..6, y -1..1 and a sign floating at 3 m over x -4..-3."""
    return box_world(floating=((-4.0, -1.0, 3.0), (-3.0, 1.0, 3.5)))


def test_free_motion_takes_distance_over_speed(world) -> None:
    robot = Robot(world, position=(0.0, 3.0, 0.7), yaw=0.0, v_max=0.5)
    result = robot.move_to((3.0, 3.0))
    assert result.reached and not result.blocked and result.waypoints_reached == 1
    assert robot.time == pytest.approx(6.0) and result.duration == pytest.approx(6.0)
    np.testing.assert_allclose(robot.position, [3.0, 3.0, 0.7])
    assert robot.distance_travelled == pytest.approx(3.0)
    # turning half a circle at 1 rad/s is slower than a 1 m step at 0.5 m/s
    result = robot.move_to((3.0, 2.0), yaw=math.pi)
    assert result.duration == pytest.approx(math.pi)
    assert robot.yaw == pytest.approx(math.pi)
    middle = robot.pose_at(6.0 + math.pi / 2)
    np.testing.assert_allclose(middle.position, [3.0, 2.5, 0.7])
    assert middle.yaw == pytest.approx(math.pi / 2)


def test_blocked_motion_stops_outside_the_obstacle(world) -> None:
    robot = Robot(world, position=(0.0, 0.0, 0.7))
    result = robot.move_to((9.0, 0.0))
    assert result.blocked and not result.reached
    assert 4.0 - 0.4 - 0.2 < robot.position[0] <= 4.0 - 0.4
    assert result.blocked_at[0] > robot.position[0]
    assert world.clearance([robot.position], "ground")[0] >= 0.4
    assert robot.time == pytest.approx(result.distance / robot.v_max)
    again = robot.move_to((9.0, 0.0))
    assert again.blocked and again.distance == pytest.approx(0.0, abs=1e-9)


def test_ground_and_aerial_modes(world) -> None:
    walker = Robot(world, position=(-3.5, -3.0, 0.7))
    assert walker.move_to((-3.5, 0.0)).reached  # walks under the floating sign
    with pytest.raises(InvalidInputError, match="cannot move to z"):
        walker.move_to((0.0, 0.0, 2.0))
    flyer = Robot(world, mode="aerial", position=(-3.5, -3.0, 3.25))
    assert flyer.move_to((-3.5, 0.0, 3.25)).blocked  # flies into it
    assert flyer.move_to((-3.5, -3.0, 1.5)).reached
    with pytest.raises(InvalidInputError, match="outside the limits"):
        flyer.move_to((0.0, 0.0, 4.9))
    with pytest.raises(InvalidInputError, match="inside an obstacle"):
        Robot(world, position=(5.0, 0.0, 0.7))
    with pytest.raises(InvalidInputError, match="mode"):
        Robot(world, mode="boat")  # type: ignore[arg-type]


def test_follow_stops_at_the_first_blocked_leg(world) -> None:
    robot = Robot(world, position=(0.0, 3.0, 0.7))
    result = robot.follow([(2.0, 3.0), (2.0, 0.0), (9.0, 0.0), (9.0, 3.0)])
    assert result.blocked and result.waypoints_reached == 2
    assert result.distance == pytest.approx(robot.distance_travelled)
    done = Robot(world, position=(0.0, 3.0, 0.7)).follow([(1.0, 3.0), (1.0, 4.0)], [0.0, 1.0])
    assert done.reached and done.waypoints_reached == 2
    with pytest.raises(InvalidInputError, match="yaws"):
        robot.follow([(1.0, 3.0)], [0.0, 1.0])


def test_log_interpolation_and_desync(world) -> None:
    robot = Robot(world, position=(0.0, 3.0, 0.7), v_max=1.0)
    robot.move_to((2.0, 3.0))
    robot.wait(1.0)
    robot.turn_to(math.pi / 2)
    late, now = robot.sensor_poses(image_time_offset_s=1.0)
    assert now.time == pytest.approx(robot.time) and now.yaw == pytest.approx(math.pi / 2)
    assert late.time == pytest.approx(robot.time - 1.0)
    assert late.yaw == pytest.approx(math.pi / 2 - 1.0)  # a second ago it was still turning
    assert robot.pose_at(1.5).position[0] == pytest.approx(1.5)  # walking at 1 m/s
    assert robot.pose_at(-5.0).time == 0.0 and robot.pose_at(1e9).time == robot.time
    trajectory = robot.trajectory
    assert trajectory.time.tolist() == pytest.approx([0.0, 2.0, 3.0, 3.0 + math.pi / 2])
    with pytest.raises(InvalidInputError):
        robot.pose_at(math.nan)


def test_drift_is_seeded_and_grows_with_distance(world) -> None:
    def final_errors(seed: int) -> tuple[float, float]:
        robot = Robot(
            world,
            position=(-8.0, -4.0, 0.7),
            odometry_drift_per_m=0.05,
            odometry_drift_per_rad=0.02,
            rng=make_rng(seed, "odometry"),
        )
        errors = []
        for _ in range(4):
            robot.follow([(-8.0, 4.0), (2.0, 4.0), (2.0, -4.0), (-8.0, -4.0)], [0.0, 1.5, 3.0, 4.5])
            errors.append(float(np.linalg.norm(robot.odometry_position - robot.position)))
        return errors[0], errors[-1]

    assert final_errors(1) == final_errors(1)
    first, last = zip(*(final_errors(seed) for seed in range(12)), strict=True)
    assert np.mean(last) > 1.3 * np.mean(first) > 0
    clean = Robot(world, position=(0.0, 3.0, 0.7))
    clean.move_to((3.0, 4.0), yaw=1.0)
    np.testing.assert_array_equal(clean.odometry_position, clean.position)
    assert clean.odometry_yaw == clean.yaw
    with pytest.raises(InvalidInputError, match="random generator"):
        Robot(world, odometry_drift_per_m=0.1)


def test_heading_error_bends_the_odometry_path(world) -> None:
    robot = Robot(world, position=(-8.0, 0.0, 0.7), odometry_drift_per_rad=0.3, rng=make_rng(0))
    robot.turn_to(math.pi)
    robot.turn_to(0.0)
    error = robot.odometry_yaw - robot.yaw
    robot.move_to((-8.0 + 10.0, 4.0))  # 10.8 m along the true path
    step = robot.odometry_position - np.array([-8.0, 0.0, 0.7])
    bend = math.atan2(step[1], step[0]) - math.atan2(4.0, 10.0)
    assert bend == pytest.approx(error, abs=1e-9)


def test_camera_orientation_pitches_nose_down(world) -> None:
    robot = Robot(world, position=(0.0, 3.0, 0.7), yaw=math.pi / 2)
    forward = Rotation.from_quat(robot.camera_orientation(pitch=0.3)).apply([1.0, 0.0, 0.0])
    np.testing.assert_allclose(forward, [0.0, math.cos(0.3), -math.sin(0.3)], atol=1e-12)


@pytest.mark.parametrize(
    ("mode", "start", "bounds"),
    [
        ("ground", (30.0, 0.0, 0.7), "x-y bounds are [-10.0, -5.0] to [10.0, 5.0]"),
        ("aerial", (0.0, -7.5, 2.0), "bounds are [-10.0, -5.0, 0.0] to [10.0, 5.0, 5.0]"),
    ],
)
def test_a_start_outside_the_world_says_so(world, mode, start, bounds) -> None:
    with pytest.raises(InvalidInputError, match="outside the world 'box'") as caught:
        Robot(world, mode=mode, position=start)
    assert "obstacle" not in str(caught.value)
    assert str(caught.value).endswith(bounds)
