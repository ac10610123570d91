"""Sweeps of xFLIE missions (worlds x scenarios x seeds x settings), one table.

A :class:`SweepSpec` (from flags or a YAML grid) expands into
:class:`~seminspect.runs.sweep.SweepTask` s, one run directory each under the sweep's
directory. :data:`MISSIONS` is the mission's part in a sweep (:mod:`seminspect.runs.sweep`
runs the tasks): a task runs, or reuses its run when
:func:`~seminspect.missions.xflie.layout.reusable_mission` says the directory holds a completed
run of the same configuration (and code), and its row holds the columns of 000 Table 3 (layer
populations, reconciled edges, detection and inspection) and Table 6 (localisation RMSE, CPU
and planning load, coverage), read from the run's typed metrics.

YAML grid::

    worlds: [city, campus]
    scenarios: [small]          # optional; default: each world's own
    seeds: [0, 1, 2]
    settings:                   # optional; any mission setting, each a list of values
      planner: [hierarchical, volumetric]
      time_budget_s: [600]
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, StrictInt, ValidationError, field_validator

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.interrupts import Interrupted
from seminspect.core.io import dumps_json, read_yaml
from seminspect.core.validation import describe_validation_error
from seminspect.missions.xflie.build import run_name
from seminspect.missions.xflie.config import (
    MissionConfig,
    is_bool_for_number,
    make_config,
    resolve,
)
from seminspect.missions.xflie.layout import read_run_metrics, reusable_mission
from seminspect.missions.xflie.metrics import MissionMetrics
from seminspect.missions.xflie.run import run_mission
from seminspect.runs.sweep import Outcome, SweepProgram, SweepTask

#: A grid without scenarios runs each world's default one.
_DEFAULT_SCENARIO: str | None = None


class SweepSpec(BaseModel):
    """The grid: every combination of world, scenario, seed and setting values is one mission."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    worlds: list[str] = Field(min_length=1)
    scenarios: list[str | None] = Field(default_factory=lambda: [_DEFAULT_SCENARIO], min_length=1)
    # strict: YAML's true would pass as seed 1 (a bool is an int to Python)
    seeds: list[StrictInt] = Field(default_factory=lambda: [0], min_length=1)
    settings: dict[str, list[Any]] = Field(default_factory=dict)

    @field_validator("settings")
    @classmethod
    def _no_bools_for_numbers(cls, settings: dict[str, list[Any]]) -> dict[str, list[Any]]:
        """A true/false for a setting that is not a switch would pass as 1 or 0."""
        for key, values in settings.items():
            if any(is_bool_for_number(MissionConfig, key, value) for value in values):
                raise ValueError(f"{key} takes no true/false, got {dumps_json(values)}")
        return settings


def load_spec(path: str | os.PathLike[str]) -> SweepSpec:
    """A YAML grid (see the module docstring); malformed files raise one-line errors."""
    document = read_yaml(path)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a mapping (worlds, scenarios, seeds, settings)")
    try:
        return SweepSpec.model_validate(document)
    except ValidationError as exc:
        raise FileFormatError(f"{path}: {describe_validation_error(exc, 'sweep')}") from None


def _slug(value: Any) -> str:
    return "".join(ch if ch.isalnum() or ch in ".-" else "_" for ch in str(value))


def expand(spec: SweepSpec, out_dir: str | os.PathLike[str]) -> list[SweepTask]:
    """Every task of the grid, each configuration validated (bad settings fail here, once).

    Run directories are absolute: Ray workers need not share the caller's working directory.
    """
    root = Path(out_dir).resolve()
    keys = sorted(spec.settings)
    for key in keys:
        if not spec.settings[key]:
            raise InvalidInputError(f"sweep setting {key!r} has no values")
    tasks = []
    seen: dict[str, str] = {}  # a resolved configuration, as JSON -> the first task's name
    for world, scenario, values in itertools.product(
        spec.worlds, spec.scenarios, itertools.product(*(spec.settings[k] for k in keys))
    ):
        chosen = dict(zip(keys, values, strict=True))
        for seed in spec.seeds:
            config = resolve(
                make_config({"world": world, "scenario": scenario, "seed": seed, **chosen})
            )
            varied = "".join(f"-{k}={_slug(v)}" for k, v in chosen.items())
            name = run_name(config) + varied
            group = f"{config.world} {config.scenario or ''}".strip()
            group += "".join(f" {k}={v}" for k, v in chosen.items())
            dumped = config.model_dump(mode="json")
            _refuse_repeat(seen, dumped, name)
            # A robot that waits for its planners' wall time moves with the machine's load.
            alone = config.charge_planning_time
            tasks.append(SweepTask(name, group, dumped, str(root / name), config.seed, alone))
    return tasks


def _refuse_repeat(seen: dict[str, str], config: dict[str, Any], name: str) -> None:
    """Refuse a second task of one resolved configuration (``1`` and ``1.0``, a seed twice):
    it would fly the same mission twice and count it twice in its group's spread."""
    key = dumps_json(config)
    if key in seen:
        same = name if seen[key] == name else f"{seen[key]} and {name}"
        raise InvalidInputError(
            f"the grid repeats a mission ({same}): a world, scenario, seed or setting value "
            "is given twice; give each once"
        )
    seen[key] = name


def run_or_reuse(
    config: MissionConfig, out: Path, progress: Callable[[Any], None] | None = None
) -> bool:
    """Make ``out`` hold a completed run of ``config``; ``True`` when an existing run was reused.

    An interrupted, failed or differently configured run is replaced, and a directory a killed
    run left (only its stale ``run.lock``, ...) is taken over, as ``seminspect mission --out``
    does (:meth:`~seminspect.runs.directory.RunDirectory.claimed`); a directory holding
    anything a run does not write is never deleted. A mission stopped by a signal raises
    :class:`~seminspect.core.interrupts.Interrupted`: the sweep stops with it.
    """
    config = resolve(config)
    if reusable_mission(out, config):
        return True
    if out.exists() and not out.is_dir():
        raise InvalidInputError(f"{out} exists and is not a run directory; move it away")
    result = run_mission(config, out, progress=progress)
    if result.stop_signal is not None:
        raise Interrupted(result.stop_signal)
    return False


#: (column, unit, figure): 000 Table 3's columns, then Table 6's.
COLUMNS: tuple[tuple[str, str, Callable[[MissionMetrics], float | None]], ...] = (
    ("target_nodes", "", lambda m: m.table3.target[0]),
    ("level_nodes", "", lambda m: m.table3.level[0]),
    ("pose_nodes", "", lambda m: m.table3.pose[0]),
    ("feature_nodes", "", lambda m: m.table3.feature[0]),
    ("unified_nodes", "", lambda m: m.table3.unified[0]),
    ("unified_edges", "", lambda m: m.table3.unified[1]),
    ("reconciled_pct", "%", lambda m: m.table3.reconciled_pct),
    ("detected_pct", "%", lambda m: m.table3.detected_pct),
    ("inspected_pct", "%", lambda m: m.table3.inspected_pct),
    ("avg_planning_ms", "ms", lambda m: m.table3.avg_planning_time_ms),
    ("rmse_xy_m", "m", lambda m: m.table6.localisation_rmse_m),
    ("cpu_load_pct", "%", lambda m: m.table6.cpu_load_pct),
    ("planning_load_pct", "%", lambda m: m.table6.planning_load_pct),
    ("coverage_pct", "%", lambda m: m.table6.surface_coverage_pct),
    ("bbox_volume_m3", "m3", lambda m: m.table6.bbox_volume_m3),
    ("sim_s", "s", lambda m: m.mission.sim_time_s),
)


def metric_figures(metrics: MissionMetrics) -> dict[str, float | None]:
    """The table's columns from a run's metrics (a figure not measured, or not finite: None)."""
    figures: dict[str, float | None] = {}
    for column, _, figure in COLUMNS:
        value = figure(metrics)
        number = None if value is None else float(value)
        figures[column] = number if number is not None and math.isfinite(number) else None
    return figures


def run_mission_task(task: SweepTask) -> bool:
    """Run or reuse one task's mission; ``True`` when a stored run was reused."""
    return run_or_reuse(MissionConfig.model_validate(task.config), Path(task.run_dir))


def mission_outcome(run_dir: Path) -> Outcome:
    """A finished mission's state and its columns."""
    metrics = read_run_metrics(run_dir)
    return metrics.state, metric_figures(metrics)


#: The xFLIE mission's part in a sweep.
MISSIONS = SweepProgram(
    run=run_mission_task,
    outcome=mission_outcome,
    columns=tuple((name, unit) for name, unit, _ in COLUMNS),
)
