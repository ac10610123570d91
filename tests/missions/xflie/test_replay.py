"""A run's LiDAR stream replayed into a bag matches the LiDAR cast directly at the same poses."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.formats.rosbag import read_bag_scans, read_label_names
from seminspect.missions.xflie.layout import load_run_world
from seminspect.missions.xflie.replay import export_run_bag, sampled_rows
from seminspect.runs.trajectory import load_trajectory
from seminspect.sensors.lidar import Lidar

pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")

COARSE = Lidar(beams=8, horizontal_resolution_deg=2.0)


def test_sampled_rows_are_a_period_apart() -> None:
    trajectory = np.zeros((7, 9))
    trajectory[:, 0] = [0.0, 0.4, 1.0, 1.1, 2.5, 2.9, 3.6]
    assert sampled_rows(trajectory, 1.0) == [0, 2, 4, 6]
    with pytest.raises(InvalidInputError, match="positive"):
        sampled_rows(trajectory, 0.0)


def test_a_replayed_bag_holds_the_lidar_at_the_true_pose(small_mission_dir, tmp_path) -> None:
    progress: list[tuple[int, int]] = []
    bag = export_run_bag(
        small_mission_dir, tmp_path / "run-bag", period_s=60.0, lidar=COARSE,
        on_scan=lambda done, total: progress.append((done, total)),
    )  # fmt: skip
    world = load_run_world(small_mission_dir)
    trajectory = load_trajectory(small_mission_dir)
    rows = trajectory[sampled_rows(trajectory, 60.0)]
    scans = list(read_bag_scans(bag, "/points", "/odom", labels_field="label"))
    assert len(scans) == len(rows) >= 2 and progress[-1] == (len(rows), len(rows))
    assert read_label_names(bag) == dict(enumerate(world.class_names))
    for row, scan in zip(rows, scans, strict=True):
        t, x, y, z, yaw, ox, oy = row[:7]
        rotation = Rotation.from_euler("z", yaw)
        direct = COARSE.scan(world, (x, y, z), rotation.as_quat(), stamp=t)
        # the bag keeps sensor-frame float32 points; put them back where the robot truly was
        in_world = rotation.apply(scan.points) + np.array([x, y, z])
        np.testing.assert_allclose(in_world, direct.points, atol=1e-4)
        np.testing.assert_array_equal(scan.labels, direct.class_id)
        np.testing.assert_allclose(scan.pose[:2, 3], [ox, oy])  # odometry, as the robot believed
        assert scan.stamp_ns == round(t * 1e9)
