"""What an xFLIE run directory holds, and reading it back.

Layout (beside the common files of :mod:`seminspect.runs.directory`)::

    <run>/
      graph.json        the final 3DLSG (seminspect.lsg JSON; `seminspect graph ...` reads it)
      snapshots/        the graph after each inspected target, named by simulated time
      map.npz           the robot's final occupancy map (seminspect.voxel-map)
      trajectory.csv    time, true and odometry pose of the robot (a team: the explorer)
      robots/           a team's robots: <robot>-trajectory.csv for each
      events.jsonl      one JSON object per decision (survey, selection, arrival, level, ...)
      metrics.json      Table 3 and Table 6 figures, mission time, distance (METRICS_FORMAT)
      summary.md        the same, for people
      images/           the view images the graph refers to
      run.mcap          with ``--record-mcap``: the run as ROS 2 messages (:mod:`.recording`)
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from seminspect.core.io import read_versioned_json
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import save_graph
from seminspect.missions.xflie.config import MissionConfig
from seminspect.missions.xflie.metrics import MissionMetrics
from seminspect.runs.directory import METRICS_FILE, RunDirectory, RunLayout, read_run_config
from seminspect.runs.reuse import Reuse, reusable_run
from seminspect.worlds import World, open_world

#: The tag of an xFLIE run's ``metrics.json`` (the name every mission has written since v1).
METRICS_FORMAT = "seminspect.run-metrics"
MAP_FILE = "map.npz"
MCAP_FILE = "run.mcap"
#: The files a finished run holds; a completed run has every one of them.
OUTPUT_FILES = (
    "graph.json", MAP_FILE, "trajectory.csv", "events.jsonl", "summary.md", METRICS_FILE,
)  # fmt: skip
XFLIE_LAYOUT = RunLayout(
    files=frozenset({"graph.json", MAP_FILE, MCAP_FILE}),
    folders={
        "snapshots": re.compile(r"graph-[\d.]+s\.json"),
        "robots": re.compile(r"[a-z]+-trajectory\.csv"),
    },
    outputs=OUTPUT_FILES,
)


def write_graph(
    run: RunDirectory, graph: LayeredSemanticGraph, snapshot_time: float | None = None
) -> Path:
    """The final graph, or a snapshot named by simulated time."""
    if snapshot_time is None:
        return save_graph(graph, run.path("graph.json"))
    return save_graph(graph, run.path(f"snapshots/graph-{snapshot_time:08.1f}s.json"))


def read_metrics_document(run_dir: Path) -> dict[str, Any]:
    """The ``metrics.json`` an xFLIE run wrote when it ended, as stored."""
    return read_versioned_json(run_dir / METRICS_FILE, METRICS_FORMAT, [1])


def read_run_metrics(run_dir: Path) -> MissionMetrics:
    """The metrics an xFLIE run wrote when it ended."""
    return MissionMetrics.from_json(read_metrics_document(run_dir))


def reusable_mission(run_dir: Path, config: MissionConfig) -> Reuse:
    """Whether ``run_dir`` holds a completed run of exactly ``config``, with its map, made by the
    same code and libraries as this process on the same kind of CPU (the reason when not)."""
    return reusable_run(run_dir, config.model_dump(mode="json"), needs=(MAP_FILE,))


def load_run_world(run_dir: Path) -> World:
    """Regenerate the world a run used (worlds are deterministic under their seed)."""
    config = read_run_config(run_dir)
    return open_world(config["world"], config["scenario"], seed=config["seed"])
