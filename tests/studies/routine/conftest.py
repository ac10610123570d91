"""Hand-made routine figures for the study's tests: one run's metrics with chosen values."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from seminspect.missions.routine.metrics import RoutineMetrics

MakeMetrics = Callable[..., RoutineMetrics]


@pytest.fixture
def make_metrics() -> MakeMetrics:
    """A factory of routine metrics: a three-task run of ``scenario`` and ``seed`` that meets
    every check, with any figure replaced by keyword (``time_s``, ``gap_pct`` and ``change``
    set the tasks' and the scenario's)."""

    def make(
        scenario: str = "nominal",
        seed: int = 0,
        *,
        time_s: float = 40.0,
        gap_pct: float | None = 1.0,
        change: dict[str, Any] | None = None,
        **figures: Any,
    ) -> RoutineMetrics:
        task = {
            "views_planned": 10, "views_repaired": 1, "views_dropped": 0, "route_length_m": 12.0,
            "views_tracked": 9, "completed": True, "skipped": "", "start_t": 0.0,
            "end_t": time_s, "coverage_pct": 90.0, "time_s": time_s,
            "tour": {} if gap_pct is None else {"gap_pct": gap_pct},
        }  # fmt: skip
        document = {
            "state": "completed", "stop_reason": "every task done",
            "scenario": {"name": scenario, "seed": seed, "change": change or {}},
            "adaptive": True, "viewpoint_utility_mean": 0.75, "view_distance_mae_m": 0.1,
            "view_distance_mae_after_deviation_m": 0.2, "roi_coverage_pct": 90.0,
            "tasks_completed": 3, "tasks_total": 3, "collisions": 0, "gamma_s_max": 0.3,
            "gamma_s_mean": 0.2, "adapted_cycles": 4, "cycles": 10,
            "rmse_before_kabsch_m": 0.4, "rmse_after_kabsch_m": 0.1,
            "planning_cycle_ms_mean": 3.0, "planning_cycle_ms_max": 9.0,
            "tour_gap_pct_max": gap_pct, "sim_time_s": 200.0, "wall_time_s": 10.0,
            "real_time_factor": 20.0,
            "tasks": [{"name": f"task-{i}", **task} for i in range(3)],
            "change_report": [],
        }  # fmt: skip
        return RoutineMetrics.from_json(document | figures)

    return make
