"""The human-readable summary of a run (``summary.md``), beside the paper's table columns."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.missions.xflie.metrics import MissionMetrics, QueryAnswer


def _fmt(value: Any, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def summary_markdown(
    metrics: MissionMetrics, graph: LayeredSemanticGraph, answers: Sequence[QueryAnswer]
) -> str:
    """Table 3 and Table 6 columns, mission figures, queries and where the time went."""
    t3, t6, m = metrics.table3, metrics.table6, metrics.mission
    targets = metrics.targets
    world = metrics.world
    pair = "/".join
    lines = [
        f"# Mission: {world.name} {world.scenario or ''} (seed {world.seed})",
        "",
        f"State: **{metrics.state}** ({metrics.stop_reason})",
        "",
        "## 3DLSG and inspection (000 Table 3 columns)",
        "",
        "| Target | Level | Pose | Feature | Total | Unified | Reconciled (%) "
        "| Detected / Inspected (%) | Avg. planning time (ms) |",
        "|---|---|---|---|---|---|---|---|---|",
        "| "
        + " | ".join(
            [
                pair(map(str, t3.target)),
                pair(map(str, t3.level)),
                pair(map(str, t3.pose)),
                pair(map(str, t3.feature)),
                pair(map(str, t3.total)),
                pair(map(str, t3.unified)),
                _fmt(t3.reconciled_pct, 1),
                f"{_fmt(t3.detected_pct, 1)} / {_fmt(t3.inspected_pct, 1)}",
                _fmt(t3.avg_planning_time_ms, 4),
            ]
        )
        + " |",
        "",
        "## Quality (000 Table 6 columns)",
        "",
        "| CPU load (%) | Surface coverage (%) | Bounding-box volume (m^3) | of true boxes "
        "| RMSE xy (m) | RMSE 3D (m) |",
        "|---|---|---|---|---|---|",
        "| "
        + " | ".join(
            [
                _fmt(t6.cpu_load_pct, 1),
                _fmt(t6.surface_coverage_pct, 1),
                _fmt(t6.bbox_volume_m3, 1),
                _fmt(t6.bbox_volume_ratio, 2),
                _fmt(t6.localisation_rmse_m, 3),
                _fmt(t6.localisation_rmse_3d_m, 3),
            ]
        )
        + " |",
        "",
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
    if answers:
        lines += [
            "",
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
    lines += [
        "",
        "## Targets",
        "",
        "| Target | Status | Levels | Poses | Features | Surface coverage (%) |",
        "|---|---|---|---|---|---|",
    ]
    coverage = t6.surface_coverage_by_target_pct
    for t in graph.targets():
        poses = [p for lv in t.levels for p in lv.poses]
        lines.append(
            f"| {t.id} | {t.status.value} | {len(t.levels)} | {len(poses)} | "
            f"{sum(len(p.features) for p in poses)} | {_fmt(coverage.get(t.id), 1)} |"
        )
    return "\n".join(lines) + "\n"
