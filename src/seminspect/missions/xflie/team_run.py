"""Running a two-robot mission (``robots = ("explorer", "inspector")``) into a run directory.

The explorer and the inspector are built like the one robot of :mod:`.build` (same world, same
start, same configuration; each has noise streams of its own) on one shared graph and one
shared occupancy map, and :class:`~seminspect.missions.xflie.team.Team` interleaves them. The
run directory holds what a one-robot run holds (``map.npz`` is the shared map,
``trajectory.csv`` the explorer's path) and ``robots/<robot>-trajectory.csv`` for each; every
event carries the robot that made it, and ``activity`` events make each robot's timeline.
``metrics.json`` holds the team's figures (mission time is the later of the two clocks;
distances, frames and scans are summed) and, under ``robots``, each robot's own.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import save_map
from seminspect.missions.xflie import MissionProgress, XFlie
from seminspect.missions.xflie.build import build_platform, mission_map
from seminspect.missions.xflie.config import ResolvedMissionConfig
from seminspect.missions.xflie.features import warn_about_feature_labels
from seminspect.missions.xflie.figures import (
    graph_figures,
    mission_figures,
    quality_figures,
    target_figures,
    truth_targets,
)
from seminspect.missions.xflie.layout import MAP_FILE, METRICS_FORMAT, OUTPUT_FILES, write_graph
from seminspect.missions.xflie.metrics import (
    CpuMeter,
    LevelEndings,
    MissionFigures,
    MissionMetrics,
    QueryAnswer,
    RunIdentity,
)
from seminspect.missions.xflie.outputs import MissionResult, write_graph_first
from seminspect.missions.xflie.queries import answer_queries
from seminspect.missions.xflie.scoring import DEFAULT_GATE_M, score_targets
from seminspect.missions.xflie.summary import summary_markdown
from seminspect.missions.xflie.team import Activity, Team, TeamRobot
from seminspect.planning.routes import warm_up
from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Detector
from seminspect.worlds import World
from seminspect.worlds.checks import warn_if_no_targets


@dataclass(frozen=True)
class RobotFigures:
    """One robot of a team: why it stopped, its own mission figures and what it did."""

    robot: str
    stop_reason: str
    mission: MissionFigures
    inspected: list[str]
    seconds_by_activity: dict[str, float]


@dataclass(frozen=True)
class TeamMetrics:
    """A team run's figures: the team's, as a one-robot run has them, and each robot's."""

    team: MissionMetrics
    robots: list[RobotFigures]

    def to_json(self) -> dict:
        """The team's ``metrics.json`` (readable as :class:`MissionMetrics`) plus ``robots``."""
        return self.team.to_json() | {"robots": {r.robot: asdict(r) for r in self.robots}}


def build_team(
    config: ResolvedMissionConfig,
    world: World,
    run: RunDirectory | None,
    progress: Callable[[MissionProgress], None] | None = None,
    detector: Detector | None = None,
) -> Team:
    """Both robots at the world's start, on one graph and one occupancy map, with their own
    clocks: they start at the same pose, so their frames coincide, and each maps for the
    other (the inspector drives through what the explorer has seen, and its own scans clear
    frontiers the explorer would otherwise visit)."""
    graph: LayeredSemanticGraph | None = None
    missions: dict[str, XFlie] = {}
    warn_if_no_targets(world, config.target_classes)
    warn_about_feature_labels(world, config.target_classes, config.feature_labels)
    shared_map = mission_map(world, config)
    for role in ("explorer", "inspector"):
        platform, ground_z = build_platform(config, world, name=role, detector=detector)
        mission = XFlie(
            config,
            platform,
            shared_map,
            ground_z=ground_z,
            run=run,
            progress=_labelled(progress, role),
            graph=graph,
            name=role,
        )
        graph = mission.graph
        missions[role] = mission

    def log(step: Activity) -> None:  # stamped with, and tagged by, the robot that did it
        missions[step.robot].recorder.event(
            "activity",
            activity=step.activity,
            start=round(step.start, 3),
            end=round(step.end, 3),
            **({} if step.target is None else {"target": step.target}),
        )

    return Team(missions["explorer"], missions["inspector"], on_step=log)


def _labelled(
    progress: Callable[[MissionProgress], None] | None, role: str
) -> Callable[[MissionProgress], None] | None:
    """Progress reports that say which robot is doing what."""
    if progress is None:
        return None
    return lambda p: progress(replace(p, phase=f"{role} {p.phase}"))


def run_team(
    run: RunDirectory,
    config: ResolvedMissionConfig,
    world: World,
    queries: Sequence[str],
    progress: Callable[[MissionProgress], None] | None,
    *,
    detector: Detector | None = None,
) -> MissionResult:
    """Run a team mission into ``run`` (claimed by the caller); queries go to the inspector."""
    team = build_team(config, world, run, progress, detector)
    warm_up()
    cpu = CpuMeter()
    inspector = team.inspector.mission
    answers: list[QueryAnswer] = []
    metrics: TeamMetrics | None = None

    def write_outputs(end: RunEnd) -> None:
        nonlocal answers, metrics
        write_graph_first(run, inspector.graph)
        answers = answer_queries(inspector, queries) if end.state == "completed" else []
        metrics = team_metrics(team, world, cpu, end, answers)
        _write_outputs(run, team, metrics, answers)

    end = conduct_run(run, team.execute, write_outputs, expected=OUTPUT_FILES, what="mission")
    return MissionResult(
        run.root,
        end.state,
        end.reason,
        None if metrics is None else metrics.team,
        inspector,
        world,
        answers,
        end.signum,
    )


def team_metrics(
    team: Team, world: World, cpu: CpuMeter, end: RunEnd, answers: Sequence[QueryAnswer]
) -> TeamMetrics:
    """The team's Table 3 / Table 6 figures over the shared graph, and each robot's own."""
    inspector = team.inspector.mission
    config = inspector.config
    gate = max(DEFAULT_GATE_M, inspector.params.d_check_T)
    score = score_targets(
        inspector.graph.targets(), truth_targets(world, config.target_classes), gate=gate
    )
    plans = [r.seconds for r in inspector.recorder.record().plans]
    robots = [robot_figures(member, team.activities, cpu) for member in team.members]
    team_figures = MissionMetrics(
        end.state,
        end.reason,
        RunIdentity(config.world, config.scenario, config.seed, inspector.platform.detector.name),
        graph_figures(inspector, score, plans),
        quality_figures(inspector, world, cpu, score),
        target_figures(score, inspector.unreachable),
        combined_figures([r.mission for r in robots], team.time, cpu),
        list(answers),
    )
    return TeamMetrics(team_figures, robots)


def robot_figures(member: TeamRobot, activities: Sequence[Activity], cpu: CpuMeter) -> RobotFigures:
    """One robot's figures, and its simulated seconds by activity (its timeline, summed)."""
    seconds: dict[str, float] = {}
    for a in activities:
        if a.robot == member.role:
            seconds[a.activity] = round(seconds.get(a.activity, 0.0) + a.end - a.start, 3)
    return RobotFigures(
        member.role,
        member.stop_reason,
        mission_figures(member.mission, cpu),
        list(member.inspected),
        seconds,
    )


def combined_figures(
    robots: Sequence[MissionFigures], sim_time: float, cpu: CpuMeter
) -> MissionFigures:
    """The team's mission figures: its time is the later clock; counts and costs add up."""
    local_plans = sum(r.local_plans for r in robots)
    local_ms = sum((r.local_planning_ms_mean or 0.0) * r.local_plans for r in robots)
    by_category: dict[str, float] = {}
    for r in robots:
        for category, seconds in r.wall_time_by_category_s.items():
            by_category[category] = round(by_category.get(category, 0.0) + seconds, 3)
    return MissionFigures(
        sim_time,
        cpu.wall_s,
        sim_time / cpu.wall_s if cpu.wall_s > 0 else None,
        sum(r.distance_m for r in robots),
        sum(r.frames for r in robots),
        sum(r.lidar_scans for r in robots),
        sum(r.collisions for r in robots),
        LevelEndings(
            sum(r.level_endings.similarity for r in robots),
            sum(r.level_endings.cap for r in robots),
        ),
        sum(r.hierarchical_queries for r in robots),
        local_plans,
        local_ms / local_plans if local_plans else None,
        sum(r.planning_wall_s for r in robots),
        robots[0].planning_time_charged,
        by_category,
    )


def team_summary(metrics: TeamMetrics) -> str:
    """The per-robot section of a team run's ``summary.md``."""
    lines = [
        "## Robots (one shared 3DLSG)",
        "",
        "| Robot | Stopped | Sim time (s) | Distance (m) | Frames | Inspected "
        "| Time by activity (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in metrics.robots:
        activities = ", ".join(f"{k} {v:.0f}" for k, v in sorted(r.seconds_by_activity.items()))
        lines.append(
            f"| {r.robot} | {r.stop_reason} | {r.mission.sim_time_s:.1f} "
            f"| {r.mission.distance_m:.1f} | {r.mission.frames} | {len(r.inspected)} "
            f"| {activities} |"
        )
    return "\n".join(lines) + "\n"


def _write_outputs(
    run: RunDirectory, team: Team, metrics: TeamMetrics, answers: Sequence[QueryAnswer]
) -> None:
    explorer, inspector = team.explorer.mission, team.inspector.mission
    write_graph(run, inspector.graph)
    save_map(run.path(MAP_FILE), explorer.occupancy)  # the map both robots built
    run.write_trajectory(explorer.platform.trajectory_rows().tolist())
    for member in team.members:
        run.write_trajectory(member.mission.platform.trajectory_rows().tolist(), member.role)
    run.flush_events()
    summary = summary_markdown(metrics.team, inspector.graph, answers)
    run.write_summary(summary + "\n" + team_summary(metrics))
    run.write_metrics(METRICS_FORMAT, metrics.to_json())  # last: it says the rest was written
