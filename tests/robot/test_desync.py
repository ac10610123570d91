"""The image/odometry desync of 000 Sec VII-B, simulated the way missions are told to."""

import math

import numpy as np
import pytest

from seminspect.robot import Robot
from seminspect.sensors import CameraModel, noise_preset, render
from sim_worlds import box_world


def test_a_late_image_tagged_with_current_odometry_misplaces_points() -> None:
    world = box_world(lower=(8.0, -6.0, 0.0), upper=(9.0, 6.0, 4.0), size=(30.0, 20.0, 5.0))
    robot = Robot(world, position=(-5.0, 0.0, 0.7), yaw=0.0)
    robot.turn_to(math.pi / 2)  # spinning in place, as during the 360-degree look-around
    robot.turn_to(0.0)
    offset = noise_preset("realistic").image_time_offset_s
    exposed, tagged = robot.sensor_poses(offset)
    assert exposed.yaw == pytest.approx(offset * robot.yaw_rate_max)  # still turning back
    frame = render(
        world,
        CameraModel(160, 120),
        exposed.position,
        exposed.quaternion,
        stamp=tagged.time,
        odometry=(tagged.odometry_position, tagged.odometry_quaternion),
    )
    wall = frame.instance > 0
    true_points = frame.points(wall)
    believed = frame.points(wall, use_odometry=True)
    np.testing.assert_allclose(true_points[:, 0], 8.0, atol=1e-4)
    # the robot places the wall rotated by the yaw it turned during the lag
    bearing = np.arctan2(believed[:, 1] - tagged.position[1], believed[:, 0] - tagged.position[0])
    truth = np.arctan2(
        true_points[:, 1] - tagged.position[1], true_points[:, 0] - tagged.position[0]
    )
    np.testing.assert_allclose(truth - bearing, offset * robot.yaw_rate_max, atol=1e-6)
