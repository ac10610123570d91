"""The human-readable summary of a run (``summary.md``), beside the paper's table columns."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.missions.xflie.metrics import (
    GraphFigures,
    MissionMetrics,
    QualityFigures,
    QueryAnswer,
)


def _fmt(value: Any, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def _row(cells: Iterable[str]) -> str:
    return "| " + " | ".join(cells) + " |"


def summary_markdown(
    metrics: MissionMetrics, graph: LayeredSemanticGraph, answers: Sequence[QueryAnswer]
) -> str:
    """Table 3 and Table 6 columns, mission figures, queries and where the time went."""
    world = metrics.world
    title = [
        f"# Mission: {world.name} {world.scenario or ''} (seed {world.seed})",
        "",
        f"State: **{metrics.state}** ({metrics.stop_reason})",
    ]
    sections = [title, _graph_table(metrics.table3), _quality_table(metrics.table6)]
    sections.append(_mission_figures(metrics))
    if answers:
        sections.append(_queries_table(answers))
    sections.append(_targets_table(graph, metrics))
    return "\n\n".join("\n".join(lines) for lines in sections) + "\n"  # a blank line between


def _graph_table(t3: GraphFigures) -> list[str]:
    counts = (t3.target, t3.level, t3.pose, t3.feature, t3.total, t3.unified)
    return [
        "## 3DLSG and inspection (000 Table 3 columns)",
        "",
        "| Target | Level | Pose | Feature | Total | Unified | Reconciled (%) "
        "| Detected / Inspected (%) | Avg. planning time (ms) |",
        "|---|---|---|---|---|---|---|---|---|",
        _row(
            [
                *("/".join(map(str, pair)) for pair in counts),
                _fmt(t3.reconciled_pct, 1),
                f"{_fmt(t3.detected_pct, 1)} / {_fmt(t3.inspected_pct, 1)}",
                _fmt(t3.avg_planning_time_ms, 4),
            ]
        ),
    ]


def _quality_table(t6: QualityFigures) -> list[str]:
    return [
        "## Quality (000 Table 6 columns)",
        "",
        "| CPU load (%) | Surface coverage (%) | Bounding-box volume (m^3) | of true boxes "
        "| RMSE xy (m) | RMSE 3D (m) |",
        "|---|---|---|---|---|---|",
        _row(
            [
                _fmt(t6.cpu_load_pct, 1),
                _fmt(t6.surface_coverage_pct, 1),
                _fmt(t6.bbox_volume_m3, 1),
                _fmt(t6.bbox_volume_ratio, 2),
                _fmt(t6.localisation_rmse_m, 3),
                _fmt(t6.localisation_rmse_3d_m, 3),
            ]
        ),
    ]


def _mission_figures(metrics: MissionMetrics) -> list[str]:
    m, targets = metrics.mission, metrics.targets
    return [
        "## Mission",
        "",
        f"- simulated time {_fmt(m.sim_time_s, 1)} s, wall time {_fmt(m.wall_time_s, 1)} s "
        f"({_fmt(m.real_time_factor, 1)}x real time), distance {_fmt(m.distance_m, 1)} m",
        f"- {m.frames} camera frames, {m.lidar_scans} LiDAR scans, "
        f"{m.collisions} motions stopped by an obstacle",
        f"- targets: {targets.true} in the world, {targets.in_graph} in the graph, "
        f"{targets.matched} matched, {targets.false_targets} false, unreachable: "
        f"{', '.join(targets.unreachable) or 'none'}",
        f"- levels ended by scene similarity (eq 8): {m.level_endings.similarity}, "
        f"by the sweep cap: {m.level_endings.cap}",
        f"- hierarchical queries: {m.hierarchical_queries}; local plans: {m.local_plans} "
        f"(mean {_fmt(m.local_planning_ms_mean, 1)} ms)",
        "",
        "Wall time by category (s): "
        + ", ".join(f"{k} {v:.1f}" for k, v in sorted(m.wall_time_by_category_s.items())),
    ]


def _queries_table(answers: Sequence[QueryAnswer]) -> list[str]:
    lines = [
        "## Operator queries",
        "",
        "| Query | Goal | Planning time (ms) | Path (m) | Reached within ε |",
        "|---|---|---|---|---|",
    ]
    for a in answers:
        time_ms = None if a.planning_time_s is None else 1e3 * a.planning_time_s
        lines.append(
            f"| {a.query} | {a.goal or a.error} | {_fmt(time_ms, 3)} | "
            f"{_fmt(a.path_length_m, 1)} | {'yes' if a.reached else 'no'} |"
        )
    return lines


def _targets_table(graph: LayeredSemanticGraph, metrics: MissionMetrics) -> list[str]:
    """One row per graph target, with the world object it was matched to: the graph names
    targets in the order it found them (000's convention), the site by its own names."""
    coverage = metrics.table6.surface_coverage_by_target_pct
    site_object = site_objects(metrics)
    lines = [
        "## Targets",
        "",
        "| Target | Site object | Status | Levels | Poses | Features | Surface coverage (%) |",
        "|---|---|---|---|---|---|---|",
    ]
    for t in graph.targets():
        poses = [p for lv in t.levels for p in lv.poses]
        lines.append(
            f"| {t.id} | {site_object.get(t.id, '- (false target)')} | {t.status.value} | "
            f"{len(t.levels)} | {len(poses)} | {sum(len(p.features) for p in poses)} | "
            f"{_fmt(coverage.get(t.id), 1)} |"
        )
    return lines


def site_objects(metrics: MissionMetrics) -> dict[str, str]:
    """Graph target id -> the name of the world object it was matched to (``metrics.json``
    keeps the pairs under ``targets.matches``, as ``target_id`` and ``truth``)."""
    return {match.target_id: match.truth for match in metrics.targets.matches}
