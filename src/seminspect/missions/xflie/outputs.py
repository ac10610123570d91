"""Writing an xFLIE run's outputs when it ends (:mod:`.layout` names the files), and what a run
hands back to its caller."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import save_map
from seminspect.missions.xflie import XFlie
from seminspect.missions.xflie.layout import MAP_FILE, METRICS_FORMAT, write_graph
from seminspect.missions.xflie.metrics import MissionMetrics, QueryAnswer
from seminspect.missions.xflie.summary import summary_markdown
from seminspect.runs.directory import RunDirectory
from seminspect.worlds import World


@dataclass
class MissionResult:
    """What a run produced (the run directory holds the same, on disk)."""

    run_dir: Path
    state: str
    reason: str
    metrics: MissionMetrics | None  # None when stopped before they could be computed
    mission: XFlie
    world: World
    answers: list[QueryAnswer] = field(default_factory=list)
    stop_signal: int | None = None  # the signal that interrupted the run, if one did


def write_graph_first(run: RunDirectory, graph: LayeredSemanticGraph) -> None:
    """End an inspection cut short and write the graph, so it survives whatever fails next."""
    if graph.inspecting is not None:
        graph.abort_inspection()
    write_graph(run, graph)


def save_outputs(
    run: RunDirectory, mission: XFlie, metrics: MissionMetrics, answers: Sequence[QueryAnswer]
) -> None:
    write_graph(run, mission.graph)
    save_map(run.path(MAP_FILE), mission.occupancy)
    run.write_trajectory(mission.platform.trajectory_rows().tolist())
    run.flush_events()
    run.write_summary(summary_markdown(metrics, mission.graph, answers))
    run.write_metrics(METRICS_FORMAT, metrics.to_json())  # last: it says the rest was written
