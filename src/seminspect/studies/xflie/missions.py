"""The city missions of the planning study (000 Sec VII-C/D): each configured as the paper ran
it, run once and reused, and Table 6's columns read from a finished run.

Table 6 runs every city scenario and seed with three planners: xFLIE, the volumetric planner
between targets in place of the hierarchical leg and local planner (the paper's "FLIE + 3DLSG +
D*+"), and pure frontier exploration that never inspects (the role of the paper's
GBPlanner2.0); planning wall time is charged to the robot's clock in every mode, under the
paper's time budget.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from seminspect.core.errors import InvalidInputError
from seminspect.missions.xflie import MissionProgress
from seminspect.missions.xflie.config import (
    CITY_BUDGETS,
    MissionConfig,
    inspects,
    make_config,
    resolve,
)
from seminspect.missions.xflie.layout import read_run_metrics
from seminspect.missions.xflie.run import run_name
from seminspect.missions.xflie.scoring import scored_matches
from seminspect.missions.xflie.sweep import run_or_reuse

CITY_SCENARIOS = ("small", "medium", "large")
#: Seeds of the Table 6 missions: the paper gives one figure per cell; three seeds show the spread.
TABLE6_SEEDS = (0, 1, 2)
#: Planners of the Table 6 missions: xFLIE, the volumetric baseline, the frontier explorer.
TABLE6_PLANNERS = ("hierarchical", "volumetric", "frontier")
#: Called with a finished step's label (``mission`` None), or with a running mission's progress.
StudyProgress = Callable[[str, MissionProgress | None], None]


def study_config(
    scenario: str, planner: str = "hierarchical", *, table6: bool = False, seed: int = 0
) -> MissionConfig:
    """The city mission of a scenario: default settings for Table 5; for Table 6 the paper's
    time budget (000 Sec VII-D: 700, 1400, 2800 s) with planning time charged."""
    if scenario not in CITY_SCENARIOS:
        raise InvalidInputError(
            f"unknown city scenario {scenario!r}; choose from {', '.join(CITY_SCENARIOS)}"
        )
    values: dict[str, Any] = {
        "world": "city",
        "scenario": scenario,
        "seed": seed,
        "planner": planner,
    }
    if table6:
        values |= {"charge_planning_time": True, "time_budget_s": CITY_BUDGETS[scenario]}
    return resolve(make_config(values))


def ensure_run(
    config: MissionConfig,
    runs_dir: str | Path,
    progress: Callable[[MissionProgress], None] | None = None,
) -> Path:
    """The run directory of ``config`` under ``runs_dir``: reused when it holds a completed run of
    the same configuration with its map, run (again) otherwise."""
    config = resolve(config)
    suffix = f"-{config.planner}" + ("-charged" if config.charge_planning_time else "")
    out = Path(runs_dir) / (run_name(config) + suffix)
    run_or_reuse(config, out, progress)
    return out


@dataclass(frozen=True)
class MissionOutcome:
    """The Table 6 columns of one mission run, and what explains them."""

    scenario: str
    planner: str
    run_dir: Path
    cpu_load_pct: float
    planning_load_pct: float | None
    planning_wall_s: float
    bbox_volume_m3: float
    surface_coverage_pct: float | None
    rmse_m: float | None
    inspected: int
    true_targets: int
    sim_time_s: float
    wall_time_s: float
    route_plans: int
    seed: int = 0
    #: Horizontal localisation error of each target Table 6 scores (inspected; for the frontier
    #: explorer, every target found), by the true object's name [m].
    inspected_errors: dict[str, float] = field(default_factory=dict)
    #: Targets in the graph that match a true object, inspected or not.
    found: int = 0

    @classmethod
    def read(cls, run_dir: Path, scenario: str, planner: str) -> MissionOutcome:
        metrics = read_run_metrics(run_dir)
        t6, mission, targets = metrics.table6, metrics.mission, metrics.targets
        scored = scored_matches(targets.matches, inspects(planner))
        return cls(
            scenario=scenario,
            planner=planner,
            run_dir=run_dir,
            cpu_load_pct=t6.cpu_load_pct,
            planning_load_pct=t6.planning_load_pct,
            planning_wall_s=mission.planning_wall_s,
            bbox_volume_m3=t6.bbox_volume_m3,
            surface_coverage_pct=t6.surface_coverage_pct,
            rmse_m=t6.localisation_rmse_m,
            inspected=targets.inspected,
            true_targets=targets.true,
            sim_time_s=mission.sim_time_s,
            wall_time_s=mission.wall_time_s,
            route_plans=mission.local_plans,
            seed=metrics.world.seed,
            inspected_errors={m.truth: m.horizontal_error for m in scored},
            found=targets.matched,
        )


def mission_study(
    scenarios: Sequence[str],
    runs_dir: str | Path,
    progress: StudyProgress | None = None,
    seeds: Sequence[int] = TABLE6_SEEDS,
    planners: Sequence[str] = TABLE6_PLANNERS,
) -> list[MissionOutcome]:
    """Each scenario and seed with each planner, planning time charged to the robot (reusing
    runs). Every planner of a seed works in the same world: the same true targets."""
    outcomes = []
    for scenario in scenarios:
        for seed in seeds:
            for planner in planners:
                label = f"Table 6 mission: {scenario}, seed {seed}, {planner}"
                config = study_config(scenario, planner, table6=True, seed=seed)
                run_dir = ensure_run(config, runs_dir, mission_progress(progress, label))
                outcomes.append(MissionOutcome.read(run_dir, scenario, planner))
                if progress is not None:
                    progress(label, None)
    return outcomes


def mission_progress(
    progress: StudyProgress | None, label: str
) -> Callable[[MissionProgress], None] | None:
    """``progress`` as one mission's callback, its reports under ``label``."""
    if progress is None:
        return None
    return lambda state: progress(label, state)
