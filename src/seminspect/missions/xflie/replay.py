"""A run's sensor stream replayed into a ROS bag, for tools that consume bags.

A run directory keeps the robot's trajectory (true and odometry poses over simulated time) and
its world is regenerated from the run's seed, so the LiDAR stream can be cast again along the
path after the mission. Each replayed scan is

* a ``PointCloud2`` in the sensor frame (the LiDAR sits at the robot's true pose, heading along
  its yaw) with a ``label`` field: the class index of every return, named on
  :data:`~seminspect.mapping.formats.rosbag.LABEL_NAMES_TOPIC` from the world's class vocabulary;
* an ``Odometry`` message with the pose the robot believed (its drifting odometry), as a real
  robot's bag would hold, stamped like the scan.

``seminspect terrain map --bag`` reads such a bag back into 001's metric-semantic cloud.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import yaw_rotation
from seminspect.mapping.formats.rosbag import BagScan
from seminspect.mapping.formats.rosbag_writer import write_bag
from seminspect.missions.xflie.layout import load_run_world
from seminspect.runs.trajectory import load_trajectory
from seminspect.sensors.lidar import Lidar
from seminspect.worlds import World

#: Seconds of simulated time between replayed scans (a 1 Hz stream keeps bags small).
DEFAULT_SCAN_PERIOD_S = 1.0


def _pose(x: float, y: float, z: float, yaw: float) -> NDArray[np.float64]:
    pose = np.eye(4)
    pose[:3, :3] = yaw_rotation(yaw).as_matrix()
    pose[:3, 3] = (x, y, z)
    return pose


def sampled_rows(trajectory: NDArray[np.float64], period_s: float) -> list[int]:
    """Rows of a trajectory at least ``period_s`` apart in time, starting with the first."""
    if not period_s > 0:
        raise InvalidInputError(f"the scan period must be positive, got {period_s}")
    rows: list[int] = []
    for index, stamp in enumerate(trajectory[:, 0]):
        if not rows or stamp >= trajectory[rows[-1], 0] + period_s:
            rows.append(index)
    return rows


def replay_scans(
    world: World,
    trajectory: NDArray[np.float64],
    lidar: Lidar,
    period_s: float = DEFAULT_SCAN_PERIOD_S,
) -> Iterator[BagScan]:
    """Scans cast from the true poses, posed by odometry (trajectory rows as in the run dir)."""
    for row in trajectory[sampled_rows(trajectory, period_s)]:
        t, x, y, z, yaw, ox, oy, oz, oyaw = row
        true_pose = _pose(x, y, z, yaw)
        orientation = Rotation.from_matrix(true_pose[:3, :3]).as_quat()
        scan = lidar.scan(world, (x, y, z), orientation, stamp=t)
        in_sensor = (scan.points - true_pose[:3, 3]) @ true_pose[:3, :3]
        yield BagScan(
            round(t * 1e9), in_sensor, scan.class_id.astype(np.int64), _pose(ox, oy, oz, oyaw)
        )


def export_run_bag(
    run_dir: str | os.PathLike[str],
    out: str | os.PathLike[str],
    period_s: float = DEFAULT_SCAN_PERIOD_S,
    lidar: Lidar | None = None,
    on_scan: Callable[[int, int], None] | None = None,
) -> Path:
    """Replay a run directory's LiDAR stream into a new ROS2 bag at ``out``."""
    root = Path(run_dir)
    trajectory = load_trajectory(root)
    if not len(trajectory):
        raise InvalidInputError(f"{root} has no trajectory to replay")
    world = load_run_world(root)
    total = len(sampled_rows(trajectory, period_s))

    def counted() -> Iterator[BagScan]:
        for done, scan in enumerate(replay_scans(world, trajectory, lidar or Lidar(), period_s)):
            yield scan
            if on_scan:
                on_scan(done + 1, total)

    return write_bag(out, counted(), dict(enumerate(world.class_names)))
