"""``seminspect bench``: studies that reproduce the papers' comparisons on this machine."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from enum import Enum
from pathlib import Path
from typing import Any

import typer

from seminspect.cli._common import console, err_console

app = typer.Typer(no_args_is_help=True)

#: Default city sizes of the scaling study (kept here so ``--help`` imports nothing heavy).
DEFAULT_SIZES = [20, 50, 100, 200, 500, 1000, 2000]


class VolumeChoice(str, Enum):
    ground = "ground"
    full = "full"


class ScenarioChoice(str, Enum):
    small = "small"
    medium = "medium"
    large = "large"


# The study's options, declared here so that its signature reads as a list of names.
_SCENARIO_OPTION = typer.Option(
    [ScenarioChoice.small, ScenarioChoice.medium, ScenarioChoice.large],
    "--scenario",
    "-s",
    help="City scenario (repeatable; default: all three).",
)
_OUT_OPTION = typer.Option(
    Path("bench-planning"), "--out", "-o", help="Where the tables, figure and JSON go."
)
_RUNS_OPTION = typer.Option(
    None, "--runs", help="Mission run directories, reused when complete (default: OUT/runs)."
)
_QUERIES_OPTION = typer.Option(9, "--queries", min=1, help="Operator queries per scenario.")
_SIZE_OPTION = typer.Option(
    DEFAULT_SIZES, "--size", help="City size (vehicles) of the scaling study (repeatable)."
)
_SCALING_OPTION = typer.Option(True, "--scaling/--no-scaling", help="Run the scaling study.")
_MISSIONS_OPTION = typer.Option(
    True, "--missions/--no-missions", help="Run the Table 6 mission comparison."
)
_SEEDS_OPTION = typer.Option(
    3, "--seeds", min=1, help="Seeds of each Table 6 mission (0, 1, ...); mean and spread."
)
_VOLUME_OPTION = typer.Option(
    VolumeChoice.ground,
    "--volume",
    help="What the volumetric baseline searches: the robot's height band (ground) or the "
    "map's whole height (full, as the paper's aerial D*+).",
)


@app.command("planning")
def planning(
    scenario: list[ScenarioChoice] = _SCENARIO_OPTION,
    out: Path = _OUT_OPTION,
    runs: Path | None = _RUNS_OPTION,
    queries: int = _QUERIES_OPTION,
    size: list[int] = _SIZE_OPTION,
    scaling: bool = _SCALING_OPTION,
    missions: bool = _MISSIONS_OPTION,
    seeds: int = _SEEDS_OPTION,
    volume: VolumeChoice = _VOLUME_OPTION,
) -> None:
    """Hierarchical versus volumetric planning: 000 Table 5, Fig 13 and Table 6 analogues.

    Runs (or reuses) the city missions and answers operator queries with both planners.

    Times both planners on synthetic cities of growing size.

    Compares whole missions with either planner and with the frontier explorer (Table 6's third
    row). Writes planning.md, planning.json, scaling.png.
    """
    from seminspect.studies.xflie.study import run_study
    from seminspect.studies.xflie.tables import write_study

    sizes = sorted(set(size)) if scaling else []
    if any(n < 2 for n in sizes):
        raise typer.BadParameter("city sizes must be at least 2 vehicles", param_hint="--size")
    names = list(dict.fromkeys(s.value for s in scenario))
    steps = len(names) * (1 + queries) + len(sizes) + (2 * len(names) * seeds if missions else 0)
    with _study_progress(steps) as show:
        study = run_study(
            names,
            runs if runs is not None else out / "runs",
            queries=queries,
            sizes=sizes,
            missions=missions,
            volume=volume.value,
            progress=show,
            seeds=list(range(seeds)),
        )
    written = write_study(study, out)
    for kind, path in written.items():
        console.print(f"{kind}: {path}", soft_wrap=True, highlight=False)


@contextlib.contextmanager
def _study_progress(steps: int) -> Iterator[Callable[[str, Any], None]]:
    """A progress bar of the study's steps; yields the study's progress callback."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.0f}/{task.total:.0f}"),
        TextColumn("{task.fields[detail]}"),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task("planning study", total=steps, detail="")

        def show(label: str, mission) -> None:
            if mission is None:
                bar.update(task, advance=1, detail=label)
            else:
                detail = f"{label}: {mission.sim_time:.0f}/{mission.budget:.0f} s simulated"
                bar.update(task, detail=detail)

        yield show
