"""The figures of a routine run (002 Sec V), typed, and its ``metrics.json``.

A routine run's ``metrics.json`` carries its own tag, :data:`METRICS_FORMAT`; runs made before
the tag existed were written under the xFLIE mission's ``seminspect.run-metrics`` and are read
too (:func:`read_routine_metrics`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_json, read_versioned_json
from seminspect.missions.routine.measures import RegionChange
from seminspect.runs.directory import METRICS_FILE

METRICS_FORMAT = "seminspect.routine-metrics"
#: The tag routine runs wrote before they had their own.
LEGACY_METRICS_FORMAT = "seminspect.run-metrics"


@dataclass(frozen=True)
class RoutineScenario:
    """The site pair a run inspected: its scenario, seed and what changed (kind and size)."""

    name: str
    seed: int
    change: dict[str, Any]


@dataclass(frozen=True)
class TaskFigures:
    """One inspection task as it ended (the executive's ``TaskRecord`` and its duration)."""

    name: str
    views_planned: int
    views_repaired: int
    views_dropped: int
    route_length_m: float | None
    views_tracked: int
    completed: bool
    skipped: str
    start_t: float | None
    end_t: float | None
    coverage_pct: float | None
    tour: dict[str, Any]
    time_s: float | None


@dataclass(frozen=True)
class RoutineMetrics:
    """Every figure of a routine run, with the change report per region, as ``metrics.json``
    holds them (:meth:`to_json`)."""

    state: str
    stop_reason: str
    scenario: RoutineScenario
    adaptive: bool
    viewpoint_utility_mean: float | None
    view_distance_mae_m: float | None
    view_distance_mae_after_deviation_m: float | None
    roi_coverage_pct: float | None
    tasks_completed: int
    tasks_total: int
    collisions: int
    gamma_s_max: float | None
    gamma_s_mean: float | None
    adapted_cycles: int
    cycles: int
    rmse_before_kabsch_m: float | None
    rmse_after_kabsch_m: float | None
    planning_cycle_ms_mean: float | None
    planning_cycle_ms_max: float | None
    tour_gap_pct_max: float | None
    sim_time_s: float
    wall_time_s: float
    real_time_factor: float | None
    tasks: list[TaskFigures]
    change_report: list[RegionChange]

    def to_json(self) -> dict[str, Any]:
        """The ``metrics.json`` content: nested dicts under the field names."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RoutineMetrics:
        """Read back what :meth:`to_json` wrote."""
        fields = {k: v for k, v in data.items() if k not in ("format", "version")}
        fields["scenario"] = RoutineScenario(**fields["scenario"])
        fields["tasks"] = [TaskFigures(**task) for task in fields["tasks"]]
        fields["change_report"] = [RegionChange(**change) for change in fields["change_report"]]
        return cls(**fields)


def read_routine_metrics(run_dir: Path) -> RoutineMetrics:
    """The metrics a routine run wrote when it ended (its own tag, or the one it had before)."""
    path = run_dir / METRICS_FILE
    legacy = _tag(path) == LEGACY_METRICS_FORMAT
    document = read_versioned_json(path, LEGACY_METRICS_FORMAT if legacy else METRICS_FORMAT, [1])
    try:
        return RoutineMetrics.from_json(document)
    except (KeyError, TypeError) as exc:
        raise FileFormatError(f"{path}: not a routine run's metrics ({exc})") from None


def _tag(path: Path) -> object:
    document = read_json(path)
    return document.get("format") if isinstance(document, dict) else None
