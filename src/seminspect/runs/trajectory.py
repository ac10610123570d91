"""A run's trajectory files: ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw`` per row.

Every program that moves a robot writes ``trajectory.csv``
(:meth:`~seminspect.runs.directory.RunDirectory.write_trajectory`); a team writes one per robot
under ``robots/``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError

TRAJECTORY_HEADER = "t,x,y,z,yaw,odom_x,odom_y,odom_z,odom_yaw"


def load_robot_trajectories(run_dir: Path) -> dict[str, NDArray[np.float64]]:
    """Each team robot's trajectory by name (empty for a one-robot run)."""
    folder = run_dir / "robots"
    paths = sorted(folder.glob("*-trajectory.csv")) if folder.is_dir() else []
    return {path.name.removesuffix("-trajectory.csv"): read_trajectory(path) for path in paths}


def load_trajectory(run_dir: Path) -> NDArray[np.float64]:
    """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw`` (none when absent)."""
    return read_trajectory(run_dir / "trajectory.csv")


def read_trajectory(path: Path) -> NDArray[np.float64]:
    """A trajectory file's rows (see :func:`load_trajectory`); none when it is absent."""
    if not path.exists():
        return np.empty((0, 9))
    try:
        return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
