"""Sweeps: many missions (worlds x scenarios x seeds x settings) as independent tasks, one table.

A :class:`SweepSpec` (from flags or a YAML grid) expands into :class:`SweepTask` s, one run
directory each under the sweep's directory. :func:`run_task` runs one task or reuses its run
when :func:`~seminspect.runs.directory.reusable_run` says the directory holds a completed run
of the same configuration (and code); it never raises, so one failed mission is one failed row.
:func:`run_on_ray` runs the tasks on a local Ray (one worker per core) or on a cluster, and
:func:`sweep_tables` writes per-run rows and mean / spread per group in the columns of
000 Table 3 (layer populations, reconciled edges, detection and inspection) and Table 6
(localisation RMSE, CPU and planning load, coverage).

YAML grid::

    worlds: [city, campus]
    scenarios: [small]          # optional; default: each world's own
    seeds: [0, 1, 2]
    settings:                   # optional; any mission setting, each a list of values
      planner: [hierarchical, volumetric]
      time_budget_s: [600]
"""

from __future__ import annotations

import csv
import io
import itertools
import logging
import math
import os
import shutil
import statistics
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.core.io import atomic_write_text, dumps_json, read_yaml
from seminspect.core.validation import describe_validation_error
from seminspect.missions.xflie.config import MissionConfig, make_config, resolve
from seminspect.missions.xflie.run import run_mission, run_name
from seminspect.runs.directory import read_metrics_document, reusable_run

TABLE_FILES = ("sweep.csv", "sweep.json", "sweep.md")
#: A grid without scenarios runs each world's default one.
_DEFAULT_SCENARIO: str | None = None


class SweepSpec(BaseModel):
    """The grid: every combination of world, scenario, seed and setting values is one mission."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    worlds: list[str] = Field(min_length=1)
    scenarios: list[str | None] = Field(default_factory=lambda: [_DEFAULT_SCENARIO], min_length=1)
    seeds: list[int] = Field(default_factory=lambda: [0], min_length=1)
    settings: dict[str, list[Any]] = Field(default_factory=dict)


def load_spec(path: str | os.PathLike[str]) -> SweepSpec:
    """A YAML grid (see the module docstring); malformed files raise one-line errors."""
    document = read_yaml(path)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a mapping (worlds, scenarios, seeds, settings)")
    try:
        return SweepSpec.model_validate(document)
    except ValidationError as exc:
        raise FileFormatError(f"{path}: {describe_validation_error(exc, 'sweep')}") from None


@dataclass(frozen=True)
class SweepTask:
    """One mission of a sweep: its resolved configuration and where it writes its run."""

    name: str
    group: str
    config: dict[str, Any]
    run_dir: str


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
            tasks.append(SweepTask(name, group, config.model_dump(mode="json"), str(root / name)))
    names = [t.name for t in tasks]
    if len(set(names)) != len(names):
        raise InvalidInputError("the grid repeats a mission (a world, scenario or seed twice)")
    return tasks


def run_or_reuse(
    config: MissionConfig, out: Path, progress: Callable[[Any], None] | None = None
) -> bool:
    """Make ``out`` hold a completed run of ``config``; ``True`` when an existing run was reused.

    A directory that is not a run is never deleted; an interrupted, failed or differently
    configured run is replaced.
    """
    config = resolve(config)
    if reusable_run(out, config):
        return True
    if out.exists():
        if not (out / "status.json").is_file():
            raise InvalidInputError(f"{out} exists and is not a run directory; move it away")
        shutil.rmtree(out)
    run_mission(config, out, progress=progress)
    return False


@dataclass
class SweepRow:
    """One task's outcome: ``state`` is the run's (completed, ...) or ``failed``."""

    name: str
    group: str
    seed: int
    state: str
    reused: bool = False
    wall_s: float = 0.0
    error: str = ""
    figures: dict[str, float | None] = field(default_factory=dict)


#: (column, unit, where in metrics.json): 000 Table 3's columns, then Table 6's.
COLUMNS: tuple[tuple[str, str, tuple[str | int, ...]], ...] = (
    ("target_nodes", "", ("table3", "target", 0)),
    ("level_nodes", "", ("table3", "level", 0)),
    ("pose_nodes", "", ("table3", "pose", 0)),
    ("feature_nodes", "", ("table3", "feature", 0)),
    ("unified_nodes", "", ("table3", "unified", 0)),
    ("unified_edges", "", ("table3", "unified", 1)),
    ("reconciled_pct", "%", ("table3", "reconciled_pct")),
    ("detected_pct", "%", ("table3", "detected_pct")),
    ("inspected_pct", "%", ("table3", "inspected_pct")),
    ("avg_planning_ms", "ms", ("table3", "avg_planning_time_ms")),
    ("rmse_xy_m", "m", ("table6", "localisation_rmse_m")),
    ("cpu_load_pct", "%", ("table6", "cpu_load_pct")),
    ("planning_load_pct", "%", ("table6", "planning_load_pct")),
    ("coverage_pct", "%", ("table6", "surface_coverage_pct")),
    ("bbox_volume_m3", "m3", ("table6", "bbox_volume_m3")),
    ("sim_s", "s", ("mission", "sim_time_s")),
)


def metric_figures(metrics: dict[str, Any]) -> dict[str, float | None]:
    """The table's columns from a run's ``metrics.json`` (missing or non-finite: ``None``)."""
    figures: dict[str, float | None] = {}
    for column, _, path in COLUMNS:
        value: Any = metrics
        for key in path:
            try:
                value = value[key]
            except (KeyError, IndexError, TypeError):
                value = None
                break
        number = float(value) if isinstance(value, int | float) else None
        figures[column] = number if number is not None and math.isfinite(number) else None
    return figures


def run_task(task: SweepTask) -> SweepRow:
    """Run or reuse one task; any failure becomes a ``failed`` row with its error line."""
    start = time.perf_counter()
    seed = int(task.config["seed"])
    try:
        out = Path(task.run_dir)
        reused = run_or_reuse(MissionConfig.model_validate(task.config), out)
        metrics = read_metrics_document(out)
        state = str(metrics.get("state", "unknown"))
        row = SweepRow(task.name, task.group, seed, state, reused, figures=metric_figures(metrics))
    except Exception as exc:  # one mission's failure must not stop the sweep
        row = SweepRow(task.name, task.group, seed, "failed", error=_error_line(exc))
    row.wall_s = time.perf_counter() - start
    return row


def _error_line(exc: Exception) -> str:
    """A user error's own line; an unexpected one with its type and where it was raised."""
    if isinstance(exc, SeminspectError):
        return str(exc)
    last = traceback.extract_tb(exc.__traceback__)[-1:]
    where = f" ({Path(last[0].filename).name}:{last[0].lineno})" if last else ""
    return f"{type(exc).__name__}: {exc}{where}"


def run_locally(
    tasks: Sequence[SweepTask], on_row: Callable[[SweepRow], None] | None = None
) -> list[SweepRow]:
    """The tasks one after another in this process (no Ray), for small sweeps and tests."""
    rows = []
    for task in tasks:
        rows.append(run_task(task))
        if on_row:
            on_row(rows[-1])
    return rows


def _ray():
    try:
        import ray  # noqa: PLC0415 - optional and heavy
    except ImportError:
        raise InvalidInputError(
            "sweeps run on Ray, which is not installed: pip install 'seminspect[sweep]'"
        ) from None
    return ray


def run_on_ray(
    tasks: Sequence[SweepTask],
    workers: int | None = None,
    address: str | None = None,
    on_row: Callable[[SweepRow], None] | None = None,
) -> list[SweepRow]:
    """Every task as a Ray task (one CPU each), in order of the tasks; rows arrive as they end.

    Without ``address`` a local Ray starts with ``workers`` CPUs (default: every core) and stops
    at the end; with one, the tasks go to that cluster, whose workers need seminspect installed.
    Missions that charge planning wall time to the robot (``charge_planning_time``) run one at a
    time, beside the others but never beside each other (:func:`_schedule`).
    """
    ray = _ray()
    if workers is not None and workers < 1:
        raise InvalidInputError(f"a sweep needs at least one worker, got {workers}")
    started_here = not ray.is_initialized()
    if started_here:
        options: dict[str, Any] = {
            "include_dashboard": False, "log_to_driver": False, "logging_level": logging.WARNING,
        }  # fmt: skip
        if address is None:
            options["num_cpus"] = workers or os.cpu_count() or 1
        try:
            ray.init(address=address, **options)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise InvalidInputError(f"cannot start or reach Ray ({exc})") from None
    try:
        slots = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        return _gather(ray, tasks, on_row, slots)
    finally:
        if started_here:
            ray.shutdown()


def charges_wall_time(task: SweepTask) -> bool:
    """Whether the task's robot waits for its planners' wall time: such a mission's figures
    move with the machine's load, so two of them never share the machine."""
    return bool(task.config.get("charge_planning_time"))


def _schedule(tasks: Sequence[SweepTask], running: Sequence[int]) -> Callable[[], int | None]:
    """The index of the next task to start given the indices ``running`` (a live view), or
    ``None`` to wait: a wall-time-charging task first whenever none runs (their chain is the
    longest, so it must never wait behind the others), else the next of the others."""
    charged = [i for i, task in enumerate(tasks) if charges_wall_time(task)]
    others = [i for i, task in enumerate(tasks) if not charges_wall_time(task)]
    charged.reverse()
    others.reverse()

    def next_index() -> int | None:
        if charged and not any(charges_wall_time(tasks[i]) for i in running):
            return charged.pop()
        return others.pop() if others else None

    return next_index


def _gather(ray, tasks: Sequence[SweepTask], on_row, slots: int) -> list[SweepRow]:
    """Run the tasks with at most ``slots`` in flight, in the order of :func:`_schedule`."""
    remote = ray.remote(num_cpus=1, max_retries=0)(run_task)
    pending: dict[Any, int] = {}
    running: list[int] = []
    next_index = _schedule(tasks, running)
    rows: list[SweepRow | None] = [None] * len(tasks)
    while True:
        while len(pending) < slots and (index := next_index()) is not None:
            pending[remote.remote(tasks[index])] = index
            running.append(index)
        if not pending:
            break
        done, _ = ray.wait(list(pending), num_returns=1)
        index = pending.pop(done[0])
        running.remove(index)
        try:
            row = ray.get(done[0])
        except Exception as exc:  # the worker itself died (killed, out of memory)
            task = tasks[index]
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            row = SweepRow(task.name, task.group, int(task.config["seed"]), "failed", error=first)
        rows[index] = row
        if on_row:
            on_row(row)
    return [row for row in rows if row is not None]


# --- the table ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class GroupSummary:
    """Mean and sample standard deviation of every column over a group's finished runs."""

    group: str
    runs: int
    failed: int
    mean: dict[str, float | None]
    spread: dict[str, float | None]


def summarise(rows: Sequence[SweepRow]) -> list[GroupSummary]:
    """One summary per group (world, scenario, settings) over its seeds, in order of first row."""
    groups: dict[str, list[SweepRow]] = {}
    for row in rows:
        groups.setdefault(row.group, []).append(row)
    summaries = []
    for group, members in groups.items():
        finished = [r for r in members if r.state != "failed"]
        mean: dict[str, float | None] = {}
        spread: dict[str, float | None] = {}
        for column, _, _ in COLUMNS:
            values = [v for r in finished if (v := r.figures.get(column)) is not None]
            mean[column] = statistics.fmean(values) if values else None
            spread[column] = statistics.stdev(values) if len(values) > 1 else None
        failed = len(members) - len(finished)
        summaries.append(GroupSummary(group, len(members), failed, mean, spread))
    return summaries


def _cell(value: float | None) -> str:
    if value is None:
        return "-"
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.3g}"


def markdown_tables(rows: Sequence[SweepRow], groups: Sequence[GroupSummary]) -> str:
    """Per-group mean ± standard deviation, then every run (000 Tables 3 and 6 columns)."""
    heads = [f"{c} ({u})" if u else c for c, u, _ in COLUMNS]
    lines = ["## Mean ± standard deviation per group", ""]
    lines += ["| group | runs | failed | " + " | ".join(heads) + " |"]
    lines += ["|---" * (3 + len(heads)) + "|"]
    for g in groups:
        cells = [
            _cell(g.mean[c]) + ("" if g.spread[c] is None else f" ± {_cell(g.spread[c])}")
            for c, _, _ in COLUMNS
        ]
        lines.append(f"| {g.group} | {g.runs} | {g.failed} | " + " | ".join(cells) + " |")
    lines += ["", "## Every run", "", "| run | seed | state | reused | " + " | ".join(heads) + " |"]
    lines += ["|---" * (4 + len(heads)) + "|"]
    for r in rows:
        cells = [_cell(r.figures.get(c)) for c, _, _ in COLUMNS]
        reused = "yes" if r.reused else "no"
        lines.append(f"| {r.name} | {r.seed} | {r.state} | {reused} | " + " | ".join(cells) + " |")
    failures = [r for r in rows if r.state == "failed"]
    if failures:
        lines += ["", "## Failed runs", ""] + [f"- {r.name}: {r.error}" for r in failures]
    return "\n".join(lines) + "\n"


def _csv(rows: Sequence[SweepRow]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    columns = [c for c, _, _ in COLUMNS]
    writer.writerow(["run", "group", "seed", "state", "reused", "wall_s", *columns, "error"])
    for r in rows:
        figures = ["" if r.figures.get(c) is None else r.figures[c] for c in columns]
        writer.writerow(
            [r.name, r.group, r.seed, r.state, r.reused, f"{r.wall_s:.1f}", *figures, r.error]
        )
    return buffer.getvalue()


def sweep_tables(rows: Sequence[SweepRow], out_dir: str | os.PathLike[str]) -> list[Path]:
    """Write ``sweep.csv`` (per run), ``sweep.json`` (runs and groups) and ``sweep.md``."""
    root = Path(out_dir)
    groups = summarise(rows)
    document = {
        "format": "seminspect.sweep",
        "version": 1,
        "runs": [asdict(r) for r in rows],
        "groups": [asdict(g) for g in groups],
    }
    return [
        atomic_write_text(root / TABLE_FILES[0], _csv(rows)),
        atomic_write_text(root / TABLE_FILES[1], dumps_json(document, indent=2) + "\n"),
        atomic_write_text(root / TABLE_FILES[2], markdown_tables(rows, groups)),
    ]
