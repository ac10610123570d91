"""Running a mission end to end and leaving a complete run directory behind.

:func:`run_mission` builds the world, the simulated robot and the executive, runs it, answers
the operator's queries, scores the result against the world's ground truth and writes
everything to the run directory. A Ctrl-C or a failure mid-mission still writes the graph and
metrics gathered so far and records why the run stopped; every file is written atomically.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from seminspect.core.errors import SeminspectError
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.config import MissionConfig, inspection_params, resolve
from seminspect.missions.evaluation import (
    DEFAULT_GATE_M,
    TargetScore,
    TruthTarget,
    score_targets,
)
from seminspect.missions.metrics import CpuMeter
from seminspect.missions.platform import SimulatedPlatform, mission_noise
from seminspect.missions.report import summary_markdown
from seminspect.missions.rundir import RunDirectory
from seminspect.missions.xflie import MissionProgress, XFlie
from seminspect.planning.local import warm_up
from seminspect.worlds import World, generate_world


@dataclass
class QueryAnswer:
    """An operator query answered after the mission and driven by the robot."""

    query: str
    goal: str | None
    planning_time_s: float | None
    path_length_m: float | None
    reached: bool
    final_distance_m: float | None
    error: str | None = None


@dataclass
class MissionResult:
    """What a run produced (the run directory holds the same, on disk)."""

    run_dir: Path
    state: str
    reason: str
    metrics: dict[str, Any]
    mission: XFlie
    world: World
    answers: list[QueryAnswer] = field(default_factory=list)


def run_name(config: MissionConfig) -> str:
    scenario = f"-{config.scenario}" if config.scenario else ""
    return f"{config.world}{scenario}-seed{config.seed}"


def build_mission(
    config: MissionConfig,
    run: RunDirectory | None,
    progress: Callable[[MissionProgress], None] | None = None,
) -> tuple[XFlie, World]:
    """The world, the robot in it and the executive, ready to run."""
    world = generate_world(config.world, config.scenario, seed=config.seed)
    params = inspection_params(config)
    # Ground robots carry the camera at body height; aerial ones start at Level-0's height.
    aerial = config.mode == "aerial"
    start_height = config.robot.flight_height if aerial else config.robot.body_height
    platform = SimulatedPlatform(
        world,
        params,
        mode=config.mode or "ground",
        noise=mission_noise(config.noise, config.odometry_drift_per_m),
        seed=config.seed,
        radius=config.robot.radius,
        speed=config.robot.speed,
        yaw_rate=config.robot.yaw_rate,
        body_height=start_height,
        camera_pitch=math.radians(camera_pitch(config)),
    )
    ground_z = float(platform.position[2] - start_height)
    occupancy = VoxelMap.covering(world, config.map_resolution)
    mission = XFlie(config, platform, occupancy, ground_z=ground_z, run=run, progress=progress)
    return mission, world


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
    """Run a mission into ``out`` (default: a fresh directory under ``base``)."""
    config = resolve(config)
    run = RunDirectory(out) if out is not None else RunDirectory.fresh(base, run_name(config))
    run.write_config(config.model_dump(mode="json"))
    run.write_status("running")
    mission, world = build_mission(config, run, progress)
    warm_up()  # compile before the clock starts: a fresh install times plans, not numba
    cpu = CpuMeter()
    state, reason, error = "completed", "", None
    try:
        reason = mission.execute()
    except KeyboardInterrupt:
        state, reason = "interrupted", "interrupted by the operator (Ctrl-C)"
    except Exception as exc:  # recorded, then re-raised once the run directory is complete
        state, reason, error = "failed", f"{type(exc).__name__}: {exc}", exc
    if mission.graph.inspecting is not None:
        mission.graph.abort_inspection()
    run.write_graph(mission.graph)  # first: the graph survives whatever fails below
    answers: list[QueryAnswer] = []
    metrics: dict[str, Any] = {}
    try:
        answers = answer_queries(mission, queries) if state == "completed" else []
        metrics = mission_metrics(mission, world, cpu, state=state, reason=reason, answers=answers)
        _write_outputs(run, mission, metrics, answers)
    except Exception as exc:
        failure = f"finishing the run failed: {type(exc).__name__}: {exc}"
        state, reason = "failed", f"{reason}; {failure}" if reason else failure
        error = error or exc
    finally:
        run.write_status(state, reason, run_dir=str(run.root))
    if error is not None:
        if isinstance(error, SeminspectError):
            raise error
        raise SeminspectError(
            f"mission failed ({reason}); partial results in {run.root}"
        ) from error
    return MissionResult(run.root, state, reason, metrics, mission, world, answers)


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
        mission.record_plan(plan.goal_id, plan)
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
) -> dict[str, Any]:
    """Every figure of a run: 000 Table 3 and Table 6 columns, and the mission's own."""
    config = mission.config
    truths = truth_targets(world, config.target_classes or ())
    # The graph merges detections within d_check^T; score on the same terms (8 m for buildings).
    gate = max(DEFAULT_GATE_M, mission.params.d_check_T)
    score = score_targets(mission.graph.targets(), truths, gate=gate)
    stats = mission.graph.population()
    planning = [r.seconds for r in mission.hierarchical]
    local = mission.navigator.stats.local_planning_s
    return {
        "state": state,
        "stop_reason": reason,
        "world": {"name": config.world, "scenario": config.scenario, "seed": config.seed},
        "table3": {
            "target": [stats.target.nodes, stats.target.edges],
            "level": [stats.level.nodes, stats.level.edges],
            "pose": [stats.pose.nodes, stats.pose.edges],
            "feature": [stats.feature.nodes, stats.feature.edges],
            "total": [stats.total.nodes, stats.total.edges],
            "unified": [stats.unified.nodes, stats.unified.edges],
            "reconciled_pct": stats.reconciled_pct,
            "detected_pct": score.detected_pct,
            "inspected_pct": score.inspected_pct,
            "avg_planning_time_ms": 1e3 * float(np.mean(planning)) if planning else None,
        },
        "table6": {
            "cpu_load_pct": cpu.load_pct(),
            "planning_load_pct": planning_load_pct(mission),
            "localisation_rmse_m": _finite(score.rmse(horizontal=True)),
            "localisation_rmse_3d_m": _finite(score.rmse(horizontal=False)),
            **coverage_metrics(mission, world, score),
        },
        "targets": {
            "true": score.truths,
            "in_graph": score.targets,
            "matched": len(score.matches),
            "inspected": sum(m.inspected for m in score.matches),
            "false_targets": score.false_targets,
            "unreachable": sorted(mission.unreachable),
            "matches": [asdict(m) for m in score.matches],
        },
        "mission": {
            "sim_time_s": mission.platform.time,
            "wall_time_s": cpu.wall_s,
            "real_time_factor": mission.platform.time / cpu.wall_s if cpu.wall_s > 0 else None,
            "distance_m": mission.platform.distance_travelled,
            "frames": mission.platform.frames,
            "lidar_scans": mission.platform.scans,
            "collisions": mission.platform.blocked_moves,
            "level_endings": mission.level_endings,
            "hierarchical_queries": len(planning),
            "local_plans": mission.navigator.stats.local_plans,
            "local_planning_ms_mean": 1e3 * float(np.mean(local)) if local else None,
            "planning_wall_s": mission.navigator.stats.planning_s,
            "planning_time_charged": config.charge_planning_time,
            "wall_time_by_category_s": {k: round(v, 3) for k, v in mission.timers.seconds.items()},
        },
        "queries": [asdict(a) for a in answers],
    }


def planning_load_pct(mission: XFlie) -> float | None:
    """Planner wall time per simulated second, in percent of one core: the load the planners
    would put on a robot running in real time."""
    sim_time = mission.platform.time
    return 100.0 * mission.navigator.stats.planning_s / sim_time if sim_time > 0 else None


def coverage_metrics(mission: XFlie, world: World, score: TargetScore) -> dict[str, Any]:
    """Surface coverage and the paper's bounding-box volume, over inspected targets."""
    by_name = {info.name: info for info in world.instances.values()}
    surface, box, truth_box = [], 0.0, 0.0
    for match in score.matches:
        if not match.inspected:
            continue
        info = by_name[match.truth]
        surface.append(mission.coverage.surface_coverage(match.target_id, world, info.id))
        box += mission.coverage.targets[match.target_id].box_volume
        truth_box += float(np.prod(info.bbox_max - info.bbox_min))
    return {
        "surface_coverage_pct": 100.0 * float(np.mean(surface)) if surface else None,
        "bbox_volume_m3": box,
        "true_bbox_volume_m3": truth_box,
        "bbox_volume_ratio": box / truth_box if truth_box else None,
    }


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _write_outputs(
    run: RunDirectory, mission: XFlie, metrics: dict[str, Any], answers: Sequence[QueryAnswer]
) -> None:
    run.write_graph(mission.graph)
    run.write_map(mission.occupancy)
    run.write_metrics(metrics)
    trajectory = mission.platform.robot.trajectory if hasattr(mission.platform, "robot") else None
    if trajectory is not None:
        rows = np.column_stack(
            [
                trajectory.time,
                trajectory.position,
                trajectory.yaw,
                trajectory.odometry_position,
                trajectory.odometry_yaw,
            ]
        )
        run.write_trajectory(rows.tolist())
    run.flush_events()
    run.write_summary(summary_markdown(metrics, mission.graph, answers))
