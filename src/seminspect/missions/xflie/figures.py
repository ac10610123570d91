"""Every figure of a finished mission, scored against the world's truth: 000 Table 3's and
Table 6's columns and the mission's own (time, distance, sensing, planning), as a typed
:class:`~seminspect.missions.xflie.metrics.MissionMetrics`."""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import numpy as np

from seminspect.missions.xflie import XFlie
from seminspect.missions.xflie.config import inspects
from seminspect.missions.xflie.metrics import (
    CpuMeter,
    GraphFigures,
    MissionFigures,
    MissionMetrics,
    QualityFigures,
    QueryAnswer,
    RunIdentity,
    TargetFigures,
)
from seminspect.missions.xflie.scoring import (
    DEFAULT_GATE_M,
    TargetScore,
    TruthTarget,
    localisation_rmse,
    score_targets,
    scored_matches,
)
from seminspect.worlds import World


def truth_targets(world: World, classes: Sequence[str]) -> list[TruthTarget]:
    """The world's target objects, located at their bounding-box centres."""
    return [
        TruthTarget(info.name, info.class_name, 0.5 * (info.bbox_min + info.bbox_max))
        for info in world.instances_of(*classes)
    ]


def mission_metrics(
    mission: XFlie,
    world: World,
    cpu: CpuMeter,
    *,
    state: str,
    reason: str,
    answers: Sequence[QueryAnswer],
) -> MissionMetrics:
    """Every figure of a run: 000 Table 3 and Table 6 columns, and the mission's own."""
    config = mission.config
    truths = truth_targets(world, config.target_classes)
    # The graph merges detections within d_check^T; score on the same terms (8 m for buildings).
    gate = max(DEFAULT_GATE_M, mission.params.d_check_T)
    score = score_targets(mission.graph.targets(), truths, gate=gate)
    record = mission.recorder.record()
    return MissionMetrics(
        state,
        reason,
        RunIdentity(config.world, config.scenario, config.seed, mission.platform.detector.name),
        graph_figures(mission, score, [r.seconds for r in record.plans]),
        quality_figures(mission, world, cpu, score),
        target_figures(score, mission.unreachable),
        mission_figures(mission, cpu),
        list(answers),
    )


def target_figures(score: TargetScore, unreachable: Collection[str]) -> TargetFigures:
    """The targets found, matched, inspected and given up on."""
    return TargetFigures(
        score.truths,
        score.targets,
        len(score.matches),
        sum(m.inspected for m in score.matches),
        score.false_targets,
        sorted(unreachable),
        list(score.matches),
    )


def graph_figures(mission: XFlie, score: TargetScore, planning: list[float]) -> GraphFigures:
    """000 Table 3's columns for the mission's graph."""
    stats = mission.graph.population()
    return GraphFigures(
        (stats.target.nodes, stats.target.edges),
        (stats.level.nodes, stats.level.edges),
        (stats.pose.nodes, stats.pose.edges),
        (stats.feature.nodes, stats.feature.edges),
        (stats.total.nodes, stats.total.edges),
        (stats.unified.nodes, stats.unified.edges),
        stats.reconciled_pct,
        score.detected_pct,
        score.inspected_pct,
        1e3 * float(np.mean(planning)) if planning else None,
    )


def quality_figures(
    mission: XFlie, world: World, cpu: CpuMeter, score: TargetScore
) -> QualityFigures:
    """000 Table 6's columns: load, localisation error, and coverage over the scored targets
    (surface coverage and the paper's bounding-box volume): those inspected, or every target
    found by a mission that only explores."""
    by_name = {info.name: info for info in world.instances.values()}
    coverage = mission.recorder.coverage
    scored = scored_matches(score.matches, inspects(mission.config.planner))
    surface: dict[str, float] = {}
    box, truth_box = 0.0, 0.0
    for match in scored:
        info = by_name[match.truth]
        surface[match.target_id] = coverage.surface_coverage(match.target_id, world, info.id)
        box += coverage.targets[match.target_id].box_volume
        truth_box += float(np.prod(info.bbox_max - info.bbox_min))
    return QualityFigures(
        cpu.load_pct(),
        planning_load_pct(mission),
        _finite(localisation_rmse(scored, horizontal=True)),
        _finite(localisation_rmse(scored, horizontal=False)),
        100.0 * float(np.mean(list(surface.values()))) if surface else None,
        box,
        truth_box,
        box / truth_box if truth_box else None,
        {target_id: 100.0 * share for target_id, share in surface.items()},
    )


def mission_figures(mission: XFlie, cpu: CpuMeter) -> MissionFigures:
    """Time, distance, sensing, level endings and planning of the mission."""
    platform, stats = mission.platform, mission.navigator.stats
    record = mission.recorder.record()
    local = stats.local_planning_s
    return MissionFigures(
        platform.time,
        cpu.wall_s,
        platform.time / cpu.wall_s if cpu.wall_s > 0 else None,
        platform.distance_travelled,
        platform.frames,
        platform.scans,
        platform.blocked_moves,
        record.level_endings,
        len(record.plans),
        stats.local_plans,
        1e3 * float(np.mean(local)) if local else None,
        stats.planning_s,
        mission.config.charge_planning_time,
        {k: round(v, 3) for k, v in record.seconds_by_category.items()},
    )


def planning_load_pct(mission: XFlie) -> float | None:
    """Planner wall time per simulated second, in percent of one core: the load the planners
    would put on a robot running in real time."""
    sim_time = mission.platform.time
    return 100.0 * mission.navigator.stats.planning_s / sim_time if sim_time > 0 else None


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None
