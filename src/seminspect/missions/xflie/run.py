"""Running a mission end to end and leaving a complete run directory behind.

:func:`run_mission` builds the world, the simulated robot and the executive, runs it, answers
the operator's queries, scores the result against the world's ground truth and writes
everything to the run directory. A Ctrl-C, a SIGTERM or a failure mid-mission still writes the
graph and metrics gathered so far and records why the run stopped; every file is written
atomically, and the last status is written after every output, so it never claims a file that
is not there.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from seminspect.core.errors import SeminspectError
from seminspect.core.interrupts import stop_on_signals
from seminspect.core.threads import sensor_threads
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie import MissionProgress, XFlie
from seminspect.missions.xflie.config import MissionConfig, ResolvedMissionConfig, inspects, resolve
from seminspect.missions.xflie.frontier import FrontierMission
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
from seminspect.missions.xflie.summary import summary_markdown
from seminspect.planning.routes import warm_up
from seminspect.platform.simulated import SimulatedPlatform, mission_noise
from seminspect.runs.directory import OUTPUT_FILES, RunDirectory, RunEnd, conduct_run
from seminspect.worlds import World, open_world
from seminspect.worlds.catalog import is_world_path


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


def run_name(config: MissionConfig) -> str:
    """``city-small-seed0``; a user world is named by its file or folder."""
    world = Path(config.world).stem if is_world_path(config.world) else config.world
    scenario = f"-{config.scenario}" if config.scenario else ""
    return f"{world}{scenario}-seed{config.seed}"


def mission_map(world: World, config: ResolvedMissionConfig) -> VoxelMap:
    """The robot's empty occupancy map over ``world``; with a second core its rays are walked
    into it on a worker thread while the mission goes on (the same map, see
    :class:`~seminspect.mapping.voxel.VoxelMap`)."""
    occupancy = VoxelMap.covering(world, config.map_resolution)
    occupancy.background = sensor_threads() > 1
    return occupancy


def build_mission(
    config: ResolvedMissionConfig,
    run: RunDirectory | None,
    progress: Callable[[MissionProgress], None] | None = None,
    world: World | None = None,
) -> tuple[XFlie, World]:
    """The world (made from ``config`` unless given), the robot in it and the executive."""
    world = world or open_world(config.world, config.scenario, seed=config.seed)
    platform, ground_z = build_platform(config, world)
    occupancy = mission_map(world, config)
    executive = XFlie if inspects(config.planner) else FrontierMission
    mission = executive(config, platform, occupancy, ground_z=ground_z, run=run, progress=progress)
    return mission, world


def build_platform(
    config: ResolvedMissionConfig, world: World, name: str | None = None
) -> tuple[SimulatedPlatform, float]:
    """The simulated robot at the world's start, and the height of the ground it stands on;
    a ``name`` gives a robot of a team noise streams of its own."""
    params = config.params
    # Ground robots carry the camera at body height; aerial ones start at Level-0's height.
    aerial = config.mode == "aerial"
    start_height = config.robot.flight_height if aerial else config.robot.body_height
    platform = SimulatedPlatform(
        world,
        params,
        mode=config.mode,
        noise=mission_noise(config.noise, config.odometry_drift_per_m),
        seed=config.seed,
        radius=config.robot.radius,
        speed=config.robot.speed,
        yaw_rate=config.robot.yaw_rate,
        body_height=start_height,
        camera_pitch=math.radians(camera_pitch(config)),
        name=name,
        threads=sensor_threads(),
    )
    return platform, float(platform.position[2] - start_height)


def camera_pitch(config: MissionConfig) -> float:
    """Camera tilt in degrees: the configured one, or 20 for aerial and 0 for ground robots."""
    if config.robot.camera_pitch_deg is not None:
        return config.robot.camera_pitch_deg
    return 20.0 if config.mode == "aerial" else 0.0


def run_mission(
    config: MissionConfig,
    out: str | os.PathLike[str] | None = None,
    *,
    base: str | os.PathLike[str] = "runs",
    queries: Sequence[str] = (),
    progress: Callable[[MissionProgress], None] | None = None,
) -> MissionResult:
    """Run a mission into ``out`` (default: a fresh directory under ``base``).

    The world is made first, so a bad world or scenario creates no directory. ``out`` is then
    claimed (see :meth:`RunDirectory.claimed`): a second run on it fails at once, and files of an
    earlier run in it are removed. Ctrl-C and SIGTERM end the mission as ``interrupted``.
    """
    config = resolve(config)
    world = open_world(config.world, config.scenario, seed=config.seed)
    with stop_on_signals():
        run = RunDirectory(out) if out is not None else RunDirectory.fresh(base, run_name(config))
        with run.claimed(config.model_dump(mode="json")):
            if config.robots:
                from seminspect.missions.xflie.team_run import run_team  # noqa: PLC0415 - it imports us

                return run_team(run, config, world, queries, progress)
            return _run(run, config, world, queries, progress)


def _run(
    run: RunDirectory,
    config: ResolvedMissionConfig,
    world: World,
    queries: Sequence[str],
    progress: Callable[[MissionProgress], None] | None,
) -> MissionResult:
    mission, world = build_mission(config, run, progress, world)
    warm_up()  # compile before the clock starts: a fresh install times plans, not numba
    cpu = CpuMeter()
    answers: list[QueryAnswer] = []
    metrics: MissionMetrics | None = None

    def write_outputs(end: RunEnd) -> None:
        nonlocal answers, metrics
        write_graph_first(run, mission.graph)
        answers = answer_queries(mission, queries) if end.state == "completed" else []
        metrics = mission_metrics(
            mission, world, cpu, state=end.state, reason=end.reason, answers=answers
        )
        _write_outputs(run, mission, metrics, answers)

    end = conduct_run(run, mission.execute, write_outputs, expected=OUTPUT_FILES, what="mission")
    return MissionResult(
        run.root, end.state, end.reason, metrics, mission, world, answers, end.signum
    )


def write_graph_first(run: RunDirectory, graph: LayeredSemanticGraph) -> None:
    """End an inspection cut short and write the graph, so it survives whatever fails next."""
    if graph.inspecting is not None:
        graph.abort_inspection()
    run.write_graph(graph)


def answer_queries(mission: XFlie, queries: Sequence[str]) -> list[QueryAnswer]:
    """Plan each query over the final graph and drive it (000 Sec V-C semantic navigation)."""
    answers = []
    epsilon = mission.params.epsilon
    for text in queries:
        try:
            plan = mission.planner.query(text, start=mission.platform.position)
        except SeminspectError as exc:
            answers.append(QueryAnswer(text, None, None, None, False, None, str(exc)))
            continue
        driven = mission.navigator.drive(plan.waypoints, plan.final_yaw)
        if not driven:
            driven = mission.navigator.go_to(
                plan.waypoints[-1], radius=0.5, final_yaw=plan.final_yaw
            )
        goal = mission.graph.node(plan.node_path[-1]).position
        distance = float(np.linalg.norm(mission.platform.position - goal))
        answers.append(
            QueryAnswer(
                text, plan.goal_id, plan.timing.total_s, plan.length, distance <= epsilon, distance
            )
        )
        mission.recorder.plan(plan.goal_id, plan)
    return answers


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
        RunIdentity(config.world, config.scenario, config.seed),
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


def _write_outputs(
    run: RunDirectory, mission: XFlie, metrics: MissionMetrics, answers: Sequence[QueryAnswer]
) -> None:
    run.write_graph(mission.graph)
    run.write_map(mission.occupancy)
    run.write_trajectory(mission.platform.trajectory_rows().tolist())
    run.flush_events()
    run.write_summary(summary_markdown(metrics, mission.graph, answers))
    run.write_metrics(
        metrics.to_json()
    )  # last: its presence says every output before it was written
