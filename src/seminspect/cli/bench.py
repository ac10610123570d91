"""``seminspect bench``: studies that reproduce the papers' comparisons on this machine."""

from __future__ import annotations

from enum import Enum
from pathlib import Path

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


@app.command("planning")
def planning(
    scenario: list[ScenarioChoice] = typer.Option(
        [ScenarioChoice.small, ScenarioChoice.medium, ScenarioChoice.large],
        "--scenario",
        "-s",
        help="City scenario (repeatable; default: all three).",
    ),
    out: Path = typer.Option(
        Path("bench-planning"), "--out", "-o", help="Where the tables, figure and JSON go."
    ),
    runs: Path | None = typer.Option(
        None, "--runs", help="Mission run directories, reused when complete (default: OUT/runs)."
    ),
    queries: int = typer.Option(9, "--queries", min=1, help="Operator queries per scenario."),
    size: list[int] = typer.Option(
        DEFAULT_SIZES, "--size", help="City size (vehicles) of the scaling study (repeatable)."
    ),
    scaling: bool = typer.Option(True, "--scaling/--no-scaling", help="Run the scaling study."),
    missions: bool = typer.Option(
        True, "--missions/--no-missions", help="Run the Table 6 mission comparison."
    ),
    seeds: int = typer.Option(
        3, "--seeds", min=1, help="Seeds of each Table 6 mission (0, 1, ...); mean and spread."
    ),
    volume: VolumeChoice = typer.Option(
        VolumeChoice.ground,
        "--volume",
        help="What the volumetric baseline searches: the robot's height band (ground) or the "
        "map's whole height (full, as the paper's aerial D*+).",
    ),
) -> None:
    """Hierarchical versus volumetric planning: 000 Table 5, Fig 13 and Table 6 analogues.

    Runs (or reuses) the city missions and answers operator queries with both planners.

    Times both planners on synthetic cities of growing size.

    Compares whole missions with either planner and with the frontier explorer (Table 6's third
    row). Writes planning.md, planning.json, scaling.png.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from seminspect.studies.xflie.study import run_study
    from seminspect.studies.xflie.tables import write_study

    sizes = sorted(set(size)) if scaling else []
    if any(n < 2 for n in sizes):
        raise typer.BadParameter("city sizes must be at least 2 vehicles", param_hint="--size")
    names = list(dict.fromkeys(s.value for s in scenario))
    steps = len(names) * (1 + queries) + len(sizes) + (2 * len(names) * seeds if missions else 0)
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
