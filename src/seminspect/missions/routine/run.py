"""Running a routine mission into a run directory, and recording ``M_H`` for one.

Layout of a routine run (beside the common files of :mod:`~seminspect.runs.directory`)::

    <run>/
      status.json, config.json, events.jsonl, summary.md, trajectory.csv
      map.npz           M_C, the map the robot built in the current world
      prior/map.npz     M_H, when the command recorded it (no --prior), or a prior read from
                        another format (.bt, .ply, .pcd) as painted onto the mission's grid
      tour.json         every task's view poses in visiting order, SA and reference lengths
      views.csv         one row per Algorithm 1 cycle (the time series of 002 Figs 8-11)
      metrics.json      the figures of 002 Sec V and the change report per region
      *.png             pictures (seminspect.report.routine)

A Ctrl-C or a failure still writes everything gathered so far and says why the run stopped.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seminspect.core.errors import InvalidInputError
from seminspect.core.interrupts import stop_on_signals
from seminspect.core.io import atomic_write_text, write_versioned_json
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.executive import RoutineMission, samples_table
from seminspect.missions.routine.live import LiveWatch
from seminspect.missions.routine.measures import region_change
from seminspect.missions.routine.metrics import (
    METRICS_FORMAT,
    RoutineMetrics,
    RoutineScenario,
    TaskFigures,
)
from seminspect.missions.routine.prior import load_prior, record_prior, save_prior
from seminspect.missions.routine.tasks import default_tasks, load_tasks
from seminspect.planning.global_views import InspectionRegion
from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import METRICS_FILE, RunDirectory, RunLayout
from seminspect.worlds.routine_sites import SitePair, mine_drift_site

TOUR_FORMAT = "seminspect.routine-tour"
MAP_FILE = "map.npz"
PRIOR_FILE = "prior/map.npz"
#: The files a finished routine run holds (metrics last, as in a mission).
ROUTINE_OUTPUTS = (
    MAP_FILE, "tour.json", "views.csv", "trajectory.csv", "events.jsonl", "summary.md",
    METRICS_FILE,
)  # fmt: skip
ROUTINE_LAYOUT = RunLayout(
    files=frozenset({MAP_FILE, "tour.json", "views.csv"}),
    folders={"prior": re.compile(r"map\.npz")},
    outputs=ROUTINE_OUTPUTS,
)


@dataclass
class RoutineResult:
    """Where a routine run went and how it ended."""

    run_dir: Path
    state: str
    reason: str
    metrics: RoutineMetrics | None  # None when stopped before the mission was built
    stop_signal: int | None = None  # the signal that interrupted the run, if one did


def routine_site(config: RoutineConfig) -> SitePair:
    """The config's built-in site pair (user pairs are passed to :func:`run_routine`)."""
    if config.world != "mine-drift":
        raise InvalidInputError(
            f"routine scenarios exist for the mine drift only, got world {config.world!r}"
        )
    return mine_drift_site(config.scenario, config.seed, config.length)


def map_site(
    config: RoutineConfig,
    out: str | os.PathLike[str],
    progress: Callable[[float], None] | None,
    site: SitePair | None = None,
) -> Path:
    """``routine map``: record ``M_H`` of the historical world (the scenario's, or ``site``'s)
    into ``out/map.npz``."""
    site = site if site is not None else routine_site(config)
    with stop_on_signals():
        run = RunDirectory(out, ROUTINE_LAYOUT)
        with run.claimed({"routine_map": config.model_dump(mode="json")}):
            prior = record_prior(site.historical, config, progress)
            path = save_prior(run.path(MAP_FILE), prior, site.historical)
            counts = prior.counts()
            run.write_summary(
                f"# M_H of {config.world} {config.scenario}, seed {config.seed}\n\n"
                f"{counts['occupied']} occupied, {counts['free']} free, {counts['unknown']} "
                f"unknown cells of {prior.resolution:g} m.\n"
            )
            run.finish("completed", "historical map recorded")
    return path


def run_routine(
    config: RoutineConfig,
    out: str | os.PathLike[str],
    *,
    prior_path: str | os.PathLike[str] | None = None,
    tasks_path: str | os.PathLike[str] | None = None,
    progress: Callable[[str, float], None] | None = None,
    site: SitePair | None = None,
    watch: LiveWatch | None = None,
) -> RoutineResult:
    """``routine inspect``: record or load ``M_H``, run Algorithm 1, write the run directory.

    ``site`` replaces the config's built-in site (a user pair, ``routine_sites.user_site``);
    ``watch``, when given, is shown the mission live from its first move (after ``M_H``).
    The directory is claimed as a mission's is (a lock, the code that ran, a heartbeat), and
    Ctrl-C or SIGTERM still leave every output gathered so far with a truthful status.
    """
    site = site if site is not None else routine_site(config)
    regions = load_tasks(tasks_path, site) if tasks_path is not None else default_tasks(site)
    # a prior that does not fit the site is refused before any run directory is made
    given = None if prior_path is None else load_prior(prior_path, config.map_resolution, site)
    settings = {
        **config.model_dump(mode="json"),
        "prior": None if prior_path is None else str(prior_path),
        "tasks": None if tasks_path is None else str(tasks_path),
    }
    with stop_on_signals():
        run = RunDirectory(out, ROUTINE_LAYOUT)
        with run.claimed(settings):
            if given is not None and Path(prior_path or "").suffix.lower() != ".npz":
                save_map(run.path(PRIOR_FILE), given)  # the grid M_C is compared with
            return _run_routine(
                run, config, site, regions, prior=given, progress=progress, watch=watch
            )


def _run_routine(
    run: RunDirectory,
    config: RoutineConfig,
    site: SitePair,
    regions: list[InspectionRegion],
    *,
    prior: VoxelMap | None,
    progress: Callable[[str, float], None] | None,
    watch: LiveWatch | None,
) -> RoutineResult:
    started = time.perf_counter()
    mission: RoutineMission | None = None
    metrics: RoutineMetrics | None = None

    def work() -> str:
        nonlocal mission
        historical = prior if prior is not None else _record_prior(config, site, run, progress)
        mission = RoutineMission(config, site, historical, regions, progress)
        if watch is not None:
            watch.attach(mission)
        return mission.execute()

    def write_outputs(end: RunEnd) -> None:
        nonlocal metrics
        if mission is not None:
            wall_s = time.perf_counter() - started
            metrics = routine_metrics(mission, site, end.state, end.reason, wall_s)
            _write_outputs(run, mission, metrics)

    end = conduct_run(run, work, write_outputs, expected=ROUTINE_LAYOUT.outputs, what="routine run")
    if watch is not None:
        watch.publish(ended=end.state, reason=end.reason)
    return RoutineResult(run.root, end.state, end.reason, metrics, end.signum)


def _record_prior(
    config: RoutineConfig,
    site: SitePair,
    run: RunDirectory,
    progress: Callable[[str, float], None] | None,
) -> VoxelMap:
    """M_H recorded on the historical site, and saved in the run directory."""
    report = None if progress is None else (lambda share: progress("mapping M_H", share))
    prior = record_prior(site.historical, config, report)
    save_prior(run.path(PRIOR_FILE), prior, site.historical)
    return prior


def _mean(values: np.ndarray) -> float | None:
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if len(finite) else None


def _max(values: np.ndarray) -> float | None:
    finite = values[np.isfinite(values)]
    return float(finite.max()) if len(finite) else None


def routine_metrics(
    mission: RoutineMission, site: SitePair, state: str, reason: str, wall_s: float
) -> RoutineMetrics:
    """Every figure of a routine run (002 Sec V), with the change report per region."""
    table = samples_table(mission.samples)
    d_view = mission.config.d_view
    error = np.abs(table["view_distance_m"].astype(float) - d_view)
    deviated = np.flatnonzero(table["gamma_s"] > mission.config.gamma_t)
    after = error[deviated[0] :] if len(deviated) else error[:0]
    coverage = [t.coverage_pct for t in mission.tasks if t.coverage_pct is not None]
    gaps = [t.tour["gap_pct"] for t in mission.tasks if "gap_pct" in t.tour]
    sim_time = mission.robot.time
    return RoutineMetrics(
        state=state,
        stop_reason=reason,
        scenario=RoutineScenario(site.name, site.seed, site.change),
        adaptive=mission.config.adapt,
        viewpoint_utility_mean=_mean(table["utility"].astype(float)),
        view_distance_mae_m=_mean(error),
        view_distance_mae_after_deviation_m=_mean(after),
        roi_coverage_pct=float(np.mean(coverage)) if coverage else None,
        tasks_completed=sum(t.completed for t in mission.tasks),
        tasks_total=len(mission.tasks),
        collisions=mission.collisions,
        gamma_s_max=_max(table["gamma_s"].astype(float)),
        gamma_s_mean=_mean(table["gamma_s"].astype(float)),
        adapted_cycles=int(table["adapted"].sum()) if len(table["adapted"]) else 0,
        cycles=len(mission.samples),
        rmse_before_kabsch_m=_mean(table["rmse_before_m"].astype(float)),
        rmse_after_kabsch_m=_mean(table["rmse_after_m"].astype(float)),
        planning_cycle_ms_mean=_mean(table["cycle_ms"].astype(float)),
        planning_cycle_ms_max=_max(table["cycle_ms"].astype(float)),
        tour_gap_pct_max=max(gaps) if gaps else None,
        sim_time_s=sim_time,
        wall_time_s=wall_s,
        real_time_factor=sim_time / wall_s if wall_s > 0 else None,
        tasks=[TaskFigures(**asdict(t), time_s=t.time_s) for t in mission.tasks],
        change_report=[
            region_change(plan.region, mission.prior, mission.current_map) for plan in mission.plans
        ],
    )


def _write_outputs(run: RunDirectory, mission: RoutineMission, metrics: RoutineMetrics) -> None:
    save_map(run.path(MAP_FILE), mission.current_map)
    tours = [
        {
            "task": plan.region.name,
            "region": plan.region.vertices.tolist(),
            "views": plan.positions.tolist(),
            "yaws": plan.yaws.tolist(),
            **record.tour,
        }
        for plan, record in zip(mission.plans, mission.tasks, strict=True)
    ]
    write_versioned_json(run.path("tour.json"), TOUR_FORMAT, 1, {"tasks": tours}, indent=2)
    table = samples_table(mission.samples)
    header = ",".join(table)
    rows = zip(*table.values(), strict=True)
    body = "".join(",".join(_cell(v) for v in row) + "\n" for row in rows)
    atomic_write_text(run.path("views.csv"), header + "\n" + body)
    trajectory = mission.robot.trajectory
    run.write_trajectory(
        np.column_stack(
            [
                trajectory.time,
                trajectory.position,
                trajectory.yaw,
                trajectory.odometry_position,
                trajectory.odometry_yaw,
            ]
        ).tolist()
    )
    for event in mission.events:
        run.log_event(
            event["event"],
            event["t"],
            **{k: v for k, v in event.items() if k not in ("t", "event")},
        )
    run.flush_events()
    run.write_summary(summary_markdown(metrics))
    run.write_metrics(METRICS_FORMAT, metrics.to_json())  # last: it says the rest was written


def _cell(value: Any) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    return "nan" if not math.isfinite(float(value)) else f"{float(value):.4f}"


def _fmt(value: float | None, unit: str = "", digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}{unit}"


def summary_markdown(metrics: RoutineMetrics) -> str:
    """The run's figures for people."""
    scenario = metrics.scenario
    mode = "adaptive (Algorithm 1)" if metrics.adaptive else "non-adaptive baseline"
    if scenario.change.get("kind") == "map":
        title = f"# Routine inspection: the site of {scenario.change.get('map')}"
    else:
        title = f"# Routine inspection: mine drift, {scenario.name}, seed {scenario.seed}"
    lines = [
        title,
        "",
        f"{metrics.state}: {metrics.stop_reason}; {mode}; change: {scenario.change}",
        "",
        "| measure | value |",
        "| --- | --- |",
        f"| tasks completed | {metrics.tasks_completed} / {metrics.tasks_total} |",
        f"| mean viewpoint utility | {_fmt(metrics.viewpoint_utility_mean)} |",
        f"| viewing-distance MAE | {_fmt(metrics.view_distance_mae_m, ' m')} |",
        f"| ROI coverage | {_fmt(metrics.roi_coverage_pct, ' %', 1)} |",
        f"| max Γ_s | {_fmt(metrics.gamma_s_max)} |",
        f"| adapted cycles | {metrics.adapted_cycles} / {metrics.cycles} |",
        f"| RMSE before / after Kabsch | {_fmt(metrics.rmse_before_kabsch_m, ' m')} / "
        f"{_fmt(metrics.rmse_after_kabsch_m, ' m')} |",
        f"| collisions | {metrics.collisions} |",
        f"| simulated / wall time | {metrics.sim_time_s:.0f} s / {metrics.wall_time_s:.1f} s |",
        "",
        "## Change between M_H and M_C per region",
        "",
        "| region | added m³ | removed m³ | compared m³ |",
        "| --- | --- | --- | --- |",
    ]
    for change in metrics.change_report:
        lines.append(
            f"| {change.region} | {change.added_m3:.2f} | {change.removed_m3:.2f} | "
            f"{change.compared_m3:.2f} |"
        )
    return "\n".join(lines) + "\n"
