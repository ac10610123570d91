"""``seminspect mission``: run an xFLIE inspection mission and show where the results are."""

from __future__ import annotations

from enum import Enum
from pathlib import Path

import typer

from seminspect.cli._common import console, err_console


class ModeChoice(str, Enum):
    ground = "ground"
    aerial = "aerial"


class NoiseChoice(str, Enum):
    ideal = "ideal"
    realistic = "realistic"


class PlannerChoice(str, Enum):
    hierarchical = "hierarchical"
    volumetric = "volumetric"


def app(
    world: str = typer.Option(
        "city", "--world", "-w", help="Built-in world (seminspect world list)."
    ),
    scenario: str | None = typer.Option(
        None, "--scenario", "-s", help="Scenario of the world (default: the world's; city: medium)."
    ),
    seed: int = typer.Option(0, "--seed", help="Seed of the world, sensors and robot.", min=0),
    preset: str | None = typer.Option(
        None,
        "--preset",
        help="urban-simulated, urban-experimental or collapsed-buildings "
        "(000 Tables 1-2); default: the world's.",
    ),
    mode: ModeChoice | None = typer.Option(
        None, "--mode", help="ground or aerial; default: the world's."
    ),
    noise: NoiseChoice = typer.Option(
        NoiseChoice.realistic, "--noise", help="Sensor noise preset."
    ),
    planner: PlannerChoice = typer.Option(
        PlannerChoice.hierarchical,
        "--planner",
        help="hierarchical (3DLSG, the default) or volumetric (the paper's baseline).",
    ),
    budget: float | None = typer.Option(
        None, "--budget", help="Time budget in simulated seconds (default: 000 Sec VII-D's).", min=1
    ),
    out: Path | None = typer.Option(
        None, "--out", "-o", help="Run directory (default: runs/<name>)."
    ),
    query: list[str] = typer.Option(
        [], "--query", "-q", help="Operator query answered after the mission (repeatable)."
    ),
    pictures: bool = typer.Option(
        True, "--pictures/--no-pictures", help="Draw the run's pictures."
    ),
) -> None:
    """Explore a site, inspect every target level by level and build its 3DLSG (paper 000).

    Writes a run directory with the graph, metrics, a summary, the trajectory and pictures.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from seminspect.missions.config import make_config
    from seminspect.missions.run import run_mission
    from seminspect.report.run_pictures import render_run

    config = make_config(
        {
            "world": world, "scenario": scenario, "seed": seed, "preset": preset,
            "mode": None if mode is None else mode.value, "noise": noise.value,
            "planner": planner.value, "time_budget_s": budget,
        }
    )  # fmt: skip
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.0f}/{task.total:.0f} s simulated"),
        TextColumn(
            "{task.fields[phase]}  targets {task.fields[detected]}/{task.fields[inspected]}"
        ),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task("mission", total=1.0, phase="start", detected=0, inspected=0)

        def show(progress) -> None:
            bar.update(
                task,
                total=progress.budget,
                completed=min(progress.sim_time, progress.budget),
                phase=progress.phase,
                detected=progress.detected,
                inspected=progress.inspected,
            )

        result = run_mission(config, out, queries=query, progress=show)
    if pictures:
        render_run(result.run_dir)
    _print_result(result)
    if result.state == "interrupted":
        err_console.print(f"interrupted; partial results in {result.run_dir}", highlight=False)
        raise typer.Exit(130)


def _print_result(result) -> None:
    metrics = result.metrics
    t3, t6, mission = metrics.table3, metrics.table6, metrics.mission
    console.print(f"[bold]{result.state}[/]: {result.reason}")
    console.print(
        f"targets detected {t3.detected_pct:.0f}%, inspected {t3.inspected_pct:.0f}% of "
        f"detected; localisation RMSE {_m(t6.localisation_rmse_m)}; "
        f"{mission.sim_time_s:.0f} s simulated in {mission.wall_time_s:.0f} s"
    )
    console.print(
        f"3DLSG: {t3.unified[0]} nodes, {t3.unified[1]} edges (reconciled {t3.reconciled_pct:.1f}%)"
    )
    for answer in result.answers:
        outcome = "reached" if answer.reached else f"not reached ({answer.error or 'too far'})"
        console.print(f"query '{answer.query}': {outcome}")
    console.print(f"results: {result.run_dir}  (summary.md, graph.json, metrics.json, *.png)")
    console.print(
        f"query the graph: seminspect graph query {result.run_dir / 'graph.json'} 'Visit ...'"
    )


def _m(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f} m"
