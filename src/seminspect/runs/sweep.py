"""Sweeps: many runs of one program as independent tasks, and one table of their figures.

A program takes part through a :class:`SweepProgram`: a function that runs (or reuses) one
task's run directory, a function that reads a finished run's state and figures from that
directory, typed, and the columns those figures fill. :func:`run_task` never raises, so one
failed run is one failed row; :func:`run_on_ray` runs the tasks on a local Ray (one worker per
core) or on a cluster, and :func:`sweep_tables` writes per-run rows and mean / spread per
group. The xFLIE mission's grid and columns are :mod:`seminspect.missions.xflie.sweep`.

A stop signal (Ctrl-C, SIGTERM) ends a sweep with :class:`SweepInterrupted`, which holds the
rows of the tasks that finished and an ``interrupted`` row for each of the others, so that the
caller can write them as a partial table (``sweep_tables(..., stopped=...)``).
"""

from __future__ import annotations

import csv
import io
import logging
import os
import signal
import statistics
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from seminspect.core.errors import InvalidInputError, SeminspectError
from seminspect.core.interrupts import (
    STOP_SIGNALS,
    Interrupted,
    as_interrupted,
    deferred_signals,
)
from seminspect.core.io import atomic_write_text, dumps_json

TABLE_FILES = ("sweep.csv", "sweep.json", "sweep.md")
#: A column of a sweep's table: its name and unit ("" when it has none).
Column = tuple[str, str]
#: What a run's directory says when it is read back: its state and its figures by column.
Outcome = tuple[str, dict[str, float | None]]
#: The state of a row whose task a stop signal kept from finishing.
INTERRUPTED = "interrupted"
#: How long a stopped sweep lets the runs it cancelled record their stop before Ray ends (s).
CANCEL_GRACE_S = 10.0


@dataclass(frozen=True)
class SweepTask:
    """One run of a sweep: its program's resolved configuration, where it writes its run, its
    seed, and whether it must have the machine to itself (its figures move with the load)."""

    name: str
    group: str
    config: dict[str, Any]
    run_dir: str
    seed: int = 0
    exclusive: bool = False


@dataclass
class SweepRow:
    """One task's outcome: ``state`` is the run's (completed, ...) or ``failed``; ``figures``
    holds the program's columns."""

    name: str
    group: str
    seed: int
    state: str
    reused: bool = False
    wall_s: float = 0.0
    error: str = ""
    figures: dict[str, float | None] = field(default_factory=dict)


@dataclass(frozen=True)
class SweepProgram:
    """How a program takes part in a sweep. Both functions must be importable by name (module
    level), since Ray sends them to its workers by reference.

    ``run`` makes ``task.run_dir`` hold a completed run of ``task.config`` and says whether an
    existing run was reused; ``outcome`` reads a finished run's state and figures, by column.
    """

    run: Callable[[SweepTask], bool]
    outcome: Callable[[Path], Outcome]
    columns: tuple[Column, ...]


class SweepInterrupted(Interrupted):
    """A stop signal ended the sweep. ``rows`` holds a row per task, in the tasks' order: the
    finished ones, and an ``interrupted`` row (with the reason) for each of the others."""

    def __init__(self, signum: int, rows: list[SweepRow]) -> None:
        super().__init__(signum)
        self.rows = rows


def _interrupted(
    tasks: Sequence[SweepTask], rows: Sequence[SweepRow | None], exc: KeyboardInterrupt
) -> SweepInterrupted:
    """The stop, with an ``interrupted`` row for every task that has no row."""
    stop = as_interrupted(exc)
    why = f"not finished: {stop.describe()}"
    padded = list(rows) + [None] * (len(tasks) - len(rows))
    return SweepInterrupted(
        stop.signum,
        [
            row or SweepRow(task.name, task.group, task.seed, INTERRUPTED, error=why)
            for task, row in zip(tasks, padded, strict=True)
        ],
    )


def run_task(task: SweepTask, program: SweepProgram) -> SweepRow:
    """Run or reuse one task; any failure becomes a ``failed`` row with its error line."""
    start = time.perf_counter()
    try:
        reused = program.run(task)
        state, figures = program.outcome(Path(task.run_dir))
        row = SweepRow(task.name, task.group, task.seed, state, reused, figures=figures)
    except Exception as exc:  # one run's failure must not stop the sweep
        row = SweepRow(task.name, task.group, task.seed, "failed", error=_error_line(exc))
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
    tasks: Sequence[SweepTask],
    program: SweepProgram,
    on_row: Callable[[SweepRow], None] | None = None,
) -> list[SweepRow]:
    """The tasks one after another in this process (no Ray), for small sweeps and tests;
    a stop signal raises :class:`SweepInterrupted`."""
    rows: list[SweepRow] = []
    try:
        for task in tasks:
            rows.append(run_task(task, program))
            if on_row:
                on_row(rows[-1])
    except KeyboardInterrupt as exc:
        raise _interrupted(tasks, rows, exc) from None
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
    program: SweepProgram,
    workers: int | None = None,
    address: str | None = None,
    on_row: Callable[[SweepRow], None] | None = None,
) -> list[SweepRow]:
    """Every task as a Ray task (one CPU each), in order of the tasks; rows arrive as they end.

    Without ``address`` a local Ray starts with ``workers`` CPUs (default: every core) and stops
    at the end; with one, the tasks go to that cluster, whose workers need seminspect installed.
    Exclusive tasks (a mission that charges planning wall time to its robot) run one at a
    time, beside the others but never beside each other (:func:`_schedule`). A stop signal
    cancels the tasks in flight, gives them :data:`CANCEL_GRACE_S` to record their stop, and
    raises :class:`SweepInterrupted`.
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
        handlers = _stop_handlers()
        try:
            ray.init(address=address, **options)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise InvalidInputError(f"cannot start or reach Ray ({exc})") from None
        finally:
            _restore(handlers)
    try:
        slots = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        return _gather(ray, tasks, program, on_row, slots)
    finally:
        if started_here:
            ray.shutdown()


def _stop_handlers() -> dict[int, Any]:
    """The stop signals' handlers now (none outside the main thread, where none can be set)."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    return {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}


def _restore(handlers: dict[int, Any]) -> None:
    """Put back the handlers ``ray.init`` replaced: its SIGTERM handler exits with 1 and its
    native one prints a stack dump, where a stopped sweep must still write its table."""
    for signum, handler in handlers.items():
        if handler is not None:  # None: set outside Python, nothing to put back
            signal.signal(signum, handler)


def _schedule(tasks: Sequence[SweepTask], running: Sequence[int]) -> Callable[[], int | None]:
    """The index of the next task to start given the indices ``running`` (a live view), or
    ``None`` to wait: an exclusive task first whenever none runs (their chain is the
    longest, so it must never wait behind the others), else the next of the others."""
    charged = [i for i, task in enumerate(tasks) if task.exclusive]
    others = [i for i, task in enumerate(tasks) if not task.exclusive]
    charged.reverse()
    others.reverse()

    def next_index() -> int | None:
        if charged and not any(tasks[i].exclusive for i in running):
            return charged.pop()
        return others.pop() if others else None

    return next_index


def _gather(
    ray, tasks: Sequence[SweepTask], program: SweepProgram, on_row, slots: int
) -> list[SweepRow]:
    """Run the tasks with at most ``slots`` in flight, in the order of :func:`_schedule`."""
    remote = ray.remote(num_cpus=1, max_retries=0)(run_task)
    pending: dict[Any, int] = {}
    running: list[int] = []
    next_index = _schedule(tasks, running)
    rows: list[SweepRow | None] = [None] * len(tasks)
    try:
        while True:
            while len(pending) < slots and (index := next_index()) is not None:
                pending[remote.remote(tasks[index], program)] = index
                running.append(index)
            if not pending:
                break
            done, _ = ray.wait(list(pending), num_returns=1)
            index = pending[done[0]]
            rows[index] = _ray_row(ray, done[0], tasks[index])
            del pending[done[0]]  # only now: a stop while getting the row must still find it
            running.remove(index)
            if on_row:
                on_row(rows[index])
    except KeyboardInterrupt as exc:
        with deferred_signals():  # a second Ctrl-C must not cut the cancellation short
            _cancel(ray, pending, tasks, rows)
        raise _interrupted(tasks, rows, exc) from None
    return [row for row in rows if row is not None]


def _ray_row(ray, ref, task: SweepTask) -> SweepRow:
    """The row a finished Ray task returned, or a failed row when its worker died."""
    try:
        return ray.get(ref)
    except Exception as exc:  # the worker itself died (killed, out of memory)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        return SweepRow(task.name, task.group, task.seed, "failed", error=first)


def _cancel(
    ray, pending: dict[Any, int], tasks: Sequence[SweepTask], rows: list[SweepRow | None]
) -> None:
    """Cancel the tasks in flight (Ray raises KeyboardInterrupt in them, so each run records
    its stop) and keep the rows of those that finish within :data:`CANCEL_GRACE_S`."""
    if not pending:
        return
    # Only what is still running: cancelling a task whose reply is on its way can trip a
    # check in Ray's core worker that aborts the driver (ray-project/ray#54846).
    finished, _ = ray.wait(list(pending), num_returns=len(pending), timeout=0)
    for ref in set(pending) - set(finished):
        ray.cancel(ref)
    done, _ = ray.wait(list(pending), num_returns=len(pending), timeout=CANCEL_GRACE_S)
    for ref in done:
        row = _ray_row(ray, ref, tasks[pending[ref]])
        if row.state != "failed":  # a cancelled task reads as a dead worker: it did not finish
            rows[pending[ref]] = row


# --- the table ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class GroupSummary:
    """Mean and sample standard deviation of every column over a group's finished runs."""

    group: str
    runs: int
    failed: int
    mean: dict[str, float | None]
    spread: dict[str, float | None]


def summarise(rows: Sequence[SweepRow], columns: Sequence[Column]) -> list[GroupSummary]:
    """One summary per group (world, scenario, settings) over its seeds, in order of first row;
    rows of tasks a stop kept from running count in no group."""
    groups: dict[str, list[SweepRow]] = {}
    for row in (r for r in rows if r.state != INTERRUPTED):
        groups.setdefault(row.group, []).append(row)
    summaries = []
    for group, members in groups.items():
        finished = [r for r in members if r.state != "failed"]
        mean: dict[str, float | None] = {}
        spread: dict[str, float | None] = {}
        for column, _ in columns:
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


def markdown_tables(
    rows: Sequence[SweepRow],
    groups: Sequence[GroupSummary],
    columns: Sequence[Column],
    stopped: str = "",
) -> str:
    """Per-group mean ± standard deviation, then every run, in the program's columns; a sweep
    ``stopped`` (the reason) is marked partial above both."""
    heads = [f"{c} ({u})" if u else c for c, u in columns]
    lines = [partial_note(rows, stopped), ""] if stopped else []
    lines += ["## Mean ± standard deviation per group", ""]
    lines += ["| group | runs | failed | " + " | ".join(heads) + " |"]
    lines += ["|---" * (3 + len(heads)) + "|"]
    for g in groups:
        cells = [
            _cell(g.mean[c]) + ("" if g.spread[c] is None else f" ± {_cell(g.spread[c])}")
            for c, _ in columns
        ]
        lines.append(f"| {g.group} | {g.runs} | {g.failed} | " + " | ".join(cells) + " |")
    lines += ["", "## Every run", "", "| run | seed | state | reused | " + " | ".join(heads) + " |"]
    lines += ["|---" * (4 + len(heads)) + "|"]
    for r in rows:
        cells = [_cell(r.figures.get(c)) for c, _ in columns]
        reused = "yes" if r.reused else "no"
        lines.append(f"| {r.name} | {r.seed} | {r.state} | {reused} | " + " | ".join(cells) + " |")
    failures = [r for r in rows if r.state == "failed"]
    if failures:
        lines += ["", "## Failed runs", ""] + [f"- {r.name}: {r.error}" for r in failures]
    return "\n".join(lines) + "\n"


def partial_note(rows: Sequence[SweepRow], stopped: str) -> str:
    """The line that marks the table of a sweep ``stopped`` (the reason) as partial."""
    finished = sum(r.state != INTERRUPTED for r in rows)
    return (
        f"**Partial table**: the sweep was {stopped}; {finished} of {len(rows)} runs finished, "
        f"the others are listed as {INTERRUPTED}."
    )


def _csv(rows: Sequence[SweepRow], columns: Sequence[Column]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    names = [c for c, _ in columns]
    writer.writerow(["run", "group", "seed", "state", "reused", "wall_s", *names, "error"])
    for r in rows:
        figures = ["" if r.figures.get(c) is None else r.figures[c] for c in names]
        writer.writerow(
            [r.name, r.group, r.seed, r.state, r.reused, f"{r.wall_s:.1f}", *figures, r.error]
        )
    return buffer.getvalue()


def sweep_tables(
    rows: Sequence[SweepRow],
    out_dir: str | os.PathLike[str],
    columns: Sequence[Column],
    stopped: str = "",
) -> list[Path]:
    """Write ``sweep.csv`` (per run), ``sweep.json`` (runs and groups) and ``sweep.md``.

    The tables of a sweep ``stopped`` by a signal (the reason) are partial: ``sweep.json``
    says so (``partial``, ``stopped``), ``sweep.md`` opens with it, and in every table the runs
    that did not finish have the state ``interrupted``.
    """
    root = Path(out_dir)
    groups = summarise(rows, columns)
    document: dict[str, Any] = {"format": "seminspect.sweep", "version": 1}
    if stopped:
        document |= {"partial": True, "stopped": stopped}
    document |= {"runs": [asdict(r) for r in rows], "groups": [asdict(g) for g in groups]}
    return [
        atomic_write_text(root / TABLE_FILES[0], _csv(rows, columns)),
        atomic_write_text(root / TABLE_FILES[1], dumps_json(document, indent=2) + "\n"),
        atomic_write_text(root / TABLE_FILES[2], markdown_tables(rows, groups, columns, stopped)),
    ]


def remove_tables(out_dir: str | os.PathLike[str]) -> None:
    """Delete an earlier sweep's tables, so that none passes for this sweep's while it runs
    (or after it was killed); each run's own directory keeps its figures."""
    for name in TABLE_FILES:
        (Path(out_dir) / name).unlink(missing_ok=True)
