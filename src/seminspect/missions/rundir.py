"""The run directory: everything one mission made, written so that it is always valid.

Layout::

    <run>/
      status.json       state (running, completed, interrupted, failed) and why it stopped
      config.json       the fully resolved mission configuration
      graph.json        the final 3DLSG (seminspect.lsg JSON; `seminspect graph ...` reads it)
      snapshots/        the graph after each inspected target, named by simulated time
      trajectory.csv    time, true and odometry pose of the robot
      events.jsonl      one JSON object per decision (survey, selection, arrival, level, ...),
                        rewritten whole at every checkpoint
      metrics.json      Table 3 and Table 6 figures, mission time, distance
      map.npz           the robot's final occupancy map (seminspect.voxel-map)
      summary.md        the same, for people
      images/           the view images the graph refers to
      *.png             pictures

Every file is written atomically (temporary file, then rename), so an interrupted or failed
run leaves the previous complete version of each file, never half of one.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import (
    atomic_write_bytes,
    atomic_write_text,
    dumps_json,
    read_versioned_json,
    write_versioned_json,
)
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import save_graph
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.missions.metrics import MissionMetrics
from seminspect.worlds import World, generate_world

if TYPE_CHECKING:
    from seminspect.missions.config import MissionConfig

STATUS_FORMAT = "seminspect.run-status"
METRICS_FORMAT = "seminspect.run-metrics"
CONFIG_FORMAT = "seminspect.mission-config"
MAP_FILE = "map.npz"


class RunDirectory:
    """Writer for one run's directory (see the module docstring)."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise InvalidInputError(f"{self.root} exists and is not a directory")
        self.root.mkdir(parents=True, exist_ok=True)
        self._events: list[dict[str, Any]] = []

    @staticmethod
    def fresh(base: str | os.PathLike[str], name: str) -> RunDirectory:
        """A new directory ``base/name``, or ``name-2``, ``name-3``, ... if it is taken."""
        parent = Path(base)
        candidate = parent / name
        suffix = 2
        while candidate.exists():
            candidate = parent / f"{name}-{suffix}"
            suffix += 1
        return RunDirectory(candidate)

    def path(self, name: str) -> Path:
        return self.root / name

    def write_status(self, state: str, reason: str = "", **details: Any) -> None:
        payload = {"state": state, "reason": reason, "updated": time.time(), **details}
        write_versioned_json(self.path("status.json"), STATUS_FORMAT, 1, payload, indent=2)

    def write_config(self, config: dict[str, Any]) -> None:
        write_versioned_json(
            self.path("config.json"), CONFIG_FORMAT, 1, {"config": config}, indent=2
        )

    def write_graph(self, graph: LayeredSemanticGraph, snapshot_time: float | None = None) -> Path:
        """The final graph, or a snapshot named by simulated time."""
        if snapshot_time is None:
            return save_graph(graph, self.path("graph.json"))
        return save_graph(graph, self.path(f"snapshots/graph-{snapshot_time:08.1f}s.json"))

    def write_metrics(self, metrics: dict[str, Any]) -> None:
        write_versioned_json(self.path("metrics.json"), METRICS_FORMAT, 1, metrics, indent=2)

    def write_map(self, occupancy: VoxelMap) -> Path:
        """The robot's occupancy map as it was at the end of the run."""
        return save_map(self.path(MAP_FILE), occupancy)

    def write_summary(self, markdown: str) -> None:
        atomic_write_text(self.path("summary.md"), markdown)

    def write_trajectory(self, rows: Sequence[Sequence[float]]) -> None:
        """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw``."""
        header = "t,x,y,z,yaw,odom_x,odom_y,odom_z,odom_yaw\n"
        body = "".join(",".join(f"{v:.4f}" for v in row) + "\n" for row in rows)
        atomic_write_text(self.path("trajectory.csv"), header + body)

    def write_image(self, name: str, image: NDArray[np.uint8]) -> str:
        """Save a view image as JPEG; returns its path relative to the run directory."""
        ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 90])
        if not ok:
            raise InvalidInputError(f"could not encode image {name}")
        relative = f"images/{name}.jpg"
        atomic_write_bytes(self.path(relative), encoded.tobytes())
        return relative

    def log_event(self, kind: str, sim_time: float, **fields: Any) -> None:
        """Record one decision; :meth:`flush_events` writes them all."""
        self._events.append({"t": round(sim_time, 3), "event": kind, **fields})

    def flush_events(self) -> None:
        """Rewrite ``events.jsonl`` atomically with every event so far."""
        lines = "".join(dumps_json(event) + "\n" for event in self._events)
        atomic_write_text(self.path("events.jsonl"), lines)

    @property
    def events(self) -> list[dict[str, Any]]:
        return list(self._events)


def read_run_config(run_dir: Path) -> dict[str, Any]:
    """The resolved mission configuration a run was made with."""
    return read_versioned_json(run_dir / "config.json", CONFIG_FORMAT, [1])["config"]


def read_run_metrics(run_dir: Path) -> MissionMetrics:
    """The metrics a run wrote when it ended."""
    return MissionMetrics.from_json(
        read_versioned_json(run_dir / "metrics.json", METRICS_FORMAT, [1])
    )


def reusable_run(run_dir: Path, config: MissionConfig) -> bool:
    """Whether ``run_dir`` holds a completed run of exactly ``config`` with its map."""
    try:
        status = read_versioned_json(run_dir / "status.json", STATUS_FORMAT, [1])
        same = read_run_config(run_dir) == config.model_dump(mode="json")
    except FileFormatError:
        return False
    return same and status.get("state") == "completed" and (run_dir / MAP_FILE).is_file()


def load_run_world(run_dir: Path) -> World:
    """Regenerate the world a run used (worlds are deterministic under their seed)."""
    config = read_run_config(run_dir)
    return generate_world(config["world"], config["scenario"], seed=config["seed"])


def load_trajectory(run_dir: Path) -> NDArray[np.float64]:
    """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw`` (none when absent)."""
    path = run_dir / "trajectory.csv"
    if not path.exists():
        return np.empty((0, 9))
    try:
        return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
