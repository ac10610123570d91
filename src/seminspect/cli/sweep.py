"""``seminspect sweep``: many missions as Ray tasks, one table of 000 Tables 3 and 6 columns."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from seminspect.cli._common import console, err_console

if TYPE_CHECKING:
    from seminspect.runs.sweep import SweepRow


def parse_seeds(text: str) -> list[int]:
    """``"0-4"``, ``"0,2,5"`` or a mix, as a sorted list of distinct seeds."""
    from seminspect.core.errors import InvalidInputError

    seeds: set[int] = set()
    for part in filter(None, (p.strip() for p in text.split(","))):
        low, dash, high = part.partition("-")
        try:
            first, last = int(low), int(high if dash else low)
        except ValueError:
            raise InvalidInputError(f"--seeds takes e.g. '0-4' or '0,2,5', got {text!r}") from None
        if first < 0 or last < first:
            raise InvalidInputError(f"--seeds range {part!r} is empty or negative")
        seeds.update(range(first, last + 1))
    if not seeds:
        raise InvalidInputError("--seeds names no seed")
    return sorted(seeds)


def parse_settings(items: list[str]) -> dict[str, list[Any]]:
    """``KEY=V1,V2`` items; values are read as YAML scalars (numbers, true/false, names).

    A key given twice is refused: keeping one of them, or both, would be a guess.
    """
    import yaml

    from seminspect.core.errors import InvalidInputError

    settings: dict[str, list[Any]] = {}
    for item in items:
        key, sep, values = item.partition("=")
        if not sep or not key.strip() or not values.strip():
            raise InvalidInputError(f"--set takes KEY=VALUE[,VALUE...], got {item!r}")
        key = key.strip()
        if key in settings:
            raise InvalidInputError(
                f"--set gives {key} twice; give all its values in one: --set {key}=A,B"
            )
        settings[key] = [yaml.safe_load(v.strip()) for v in values.split(",")]
    return settings


# The command's options, declared here so that its signature reads as a list of names.
_GRID_OPTION = typer.Option(
    None, "--grid", help="YAML grid: worlds, scenarios, seeds, settings (see docs/sweeps.md)."
)
_WORLD_OPTION = typer.Option([], "--world", "-w", help="World (repeatable).")
_SCENARIO_OPTION = typer.Option([], "--scenario", "-s", help="Scenario (repeatable).")
_SEEDS_OPTION = typer.Option("0", "--seeds", help="Seeds, e.g. '0-4' or '0,2,5'.")
_SET_OPTION = typer.Option(
    [], "--set", help="Mission setting and its values, e.g. planner=hierarchical,volumetric."
)
_OUT_OPTION = typer.Option(Path("runs/sweep"), "--out", "-o", help="Sweep directory.")
_WORKERS_OPTION = typer.Option(
    None, "--workers", min=1, help="Local Ray workers (default: one per core)."
)
_ADDRESS_OPTION = typer.Option(
    None, "--address", help="Address of a running Ray cluster (e.g. ray://head:10001)."
)
_LOCAL_OPTION = typer.Option(
    False, "--local", help="Run the missions one after another in this process, without Ray."
)


def app(
    grid: Path | None = _GRID_OPTION,
    world: list[str] = _WORLD_OPTION,
    scenario: list[str] = _SCENARIO_OPTION,
    seeds: str = _SEEDS_OPTION,
    setting: list[str] = _SET_OPTION,
    out: Path = _OUT_OPTION,
    workers: int | None = _WORKERS_OPTION,
    address: str | None = _ADDRESS_OPTION,
    local: bool = _LOCAL_OPTION,
) -> None:
    """Run every mission of a grid (worlds x scenarios x seeds x settings) as Ray tasks.

    Each mission writes its own run directory under --out and finished runs of the same
    configuration are reused; a failed mission is reported and the sweep goes on. Writes
    sweep.csv, sweep.json and sweep.md (per-run rows, mean and spread per group); Ctrl-C or
    SIGTERM writes them as partial tables, the missions not finished marked interrupted.
    """
    from seminspect.core.errors import InvalidInputError
    from seminspect.core.interrupts import deferred_signals
    from seminspect.missions.xflie.sweep import MISSIONS, expand
    from seminspect.runs.sweep import (
        SweepInterrupted,
        remove_tables,
        run_locally,
        run_on_ray,
    )

    if local and (workers is not None or address is not None):
        raise InvalidInputError("--local runs in this process: drop --workers and --address")
    tasks = expand(_sweep_spec(grid, world, scenario, seeds, setting), out)
    out.mkdir(parents=True, exist_ok=True)
    remove_tables(out)  # an earlier sweep's table must not pass for this one's
    try:
        with _sweep_progress(len(tasks)) as show:
            if local:
                rows = run_locally(tasks, MISSIONS, on_row=show)
            else:
                rows = run_on_ray(tasks, MISSIONS, workers=workers, address=address, on_row=show)
    except SweepInterrupted as stop:
        with deferred_signals():  # a second signal must not cut the partial tables short
            _show_tables(stop.rows, out, stop.describe())
        raise
    if _show_tables(rows, out):
        raise typer.Exit(1)


def _show_tables(rows: list[SweepRow], out: Path, stopped: str = "") -> int:
    """Write and print the tables (partial when ``stopped``) and the failures; how many failed."""
    from seminspect.missions.xflie.sweep import MISSIONS
    from seminspect.runs.sweep import partial_note, sweep_tables

    written = sweep_tables(rows, out, MISSIONS.columns, stopped)
    console.print((out / "sweep.md").read_text(encoding="utf-8"), markup=False, highlight=False)
    console.print(f"tables: {', '.join(str(p) for p in written)}", highlight=False)
    failures = [r for r in rows if r.state == "failed"]
    for row in failures:
        err_console.print(f"failed: {row.name}: {row.error}", highlight=False, soft_wrap=True)
    if failures:
        err_console.print(f"{len(failures)} of {len(rows)} missions failed", highlight=False)
    if stopped:
        note = partial_note(rows, stopped).replace("**", "")
        err_console.print(note, highlight=False, soft_wrap=True)
    return len(failures)


def _sweep_spec(
    grid: Path | None, world: list[str], scenario: list[str], seeds: str, setting: list[str]
):
    """The grid of a YAML file, or of the command line's flags (not both)."""
    from pydantic import ValidationError

    from seminspect.core.errors import InvalidInputError
    from seminspect.core.validation import describe_validation_error
    from seminspect.missions.xflie.sweep import SweepSpec, load_spec

    if grid is not None:
        if world or scenario or setting:
            raise InvalidInputError("give either --grid or --world/--scenario/--set, not both")
        return load_spec(grid)
    try:
        return SweepSpec(
            worlds=world or ["city"],
            scenarios=list(scenario) or [None],
            seeds=parse_seeds(seeds),
            settings=parse_settings(setting),
        )
    except ValidationError as exc:
        raise InvalidInputError(describe_validation_error(exc, "sweep")) from None


@contextlib.contextmanager
def _sweep_progress(total: int) -> Iterator[Callable[[Any], None]]:
    """A progress bar of finished and failed missions; yields the per-row callback."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (
        TextColumn("[bold]sweep"), BarColumn(), MofNCompleteColumn(),
        TextColumn("missions  {task.fields[failed]} failed  {task.fields[last]}"),
        TimeElapsedColumn(),
    )  # fmt: skip
    with Progress(*columns, console=err_console, transient=True) as progress:
        bar = progress.add_task("sweep", total=total, failed=0, last="")
        failed = 0

        def show(row) -> None:
            nonlocal failed
            failed += row.state == "failed"
            progress.update(bar, advance=1, failed=failed, last=f"{row.name}: {row.state}")

        yield show
