"""``seminspect routine``: routine inspection on an outdated map (paper 002)."""

from __future__ import annotations

from pathlib import Path

import typer

from seminspect.cli._common import console, err_console

app = typer.Typer(no_args_is_help=True, help="Routine inspection on an outdated map (002).")

_WORLD = typer.Option("mine-drift", "--world", "-w", help="Site (mine-drift).")
_SCENARIO = typer.Option(
    "nominal", "--scenario", "-s", help="nominal, receding, advancing or obstructed."
)
_SEED = typer.Option(0, "--seed", help="Seed of the site and the tour.", min=0)
_LENGTH = typer.Option(20.0, "--length", help="Drift length [m].", min=10, max=200)


def _progress_bar():
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TimeElapsedColumn(),
        console=err_console,
        transient=True,
    )


@app.command("map")
def map_command(
    world: str = _WORLD,
    scenario: str = _SCENARIO,
    seed: int = _SEED,
    length: float = _LENGTH,
    out: Path = typer.Option(..., "--out", "-o", help="Directory for the map (map.npz)."),
) -> None:
    """Record M_H: a mapping traverse through the scenario's historical world."""
    from seminspect.missions.routine import RoutineConfig
    from seminspect.missions.routine_run import map_site

    config = RoutineConfig(world=world, scenario=scenario, seed=seed, length=length)
    with _progress_bar() as bar:
        task = bar.add_task("mapping M_H", total=1.0)
        path = map_site(config, out, lambda share: bar.update(task, completed=share))
    console.print(f"M_H recorded: {path}")
    console.print(f"inspect with: seminspect routine inspect --scenario {scenario} --prior {path}")


@app.command("inspect")
def inspect_command(
    world: str = _WORLD,
    scenario: str = _SCENARIO,
    seed: int = _SEED,
    length: float = _LENGTH,
    prior: Path | None = typer.Option(
        None, "--prior", help="M_H (.npz, .bt, .ply, .pcd); default: record it first."
    ),
    tasks: Path | None = typer.Option(
        None, "--tasks", help="YAML/JSON task file of regions; default: the scenario's."
    ),
    adapt: bool = typer.Option(
        True, "--adapt/--no-adapt", help="Algorithm 1, or track the global tour directly."
    ),
    compare: bool = typer.Option(
        False, "--compare", help="Run adaptive and non-adaptive into OUT/adaptive, OUT/baseline."
    ),
    out: Path = typer.Option(..., "--out", "-o", help="Run directory."),
    pictures: bool = typer.Option(True, "--pictures/--no-pictures", help="Draw the pictures."),
) -> None:
    """Inspect the scenario's regions in the current world with a plan made on M_H."""
    from seminspect.missions.routine import RoutineConfig
    from seminspect.missions.routine_run import PRIOR_FILE, run_routine
    from seminspect.report.figures import save_figure
    from seminspect.report.routine import comparison_figure, render_routine

    base = RoutineConfig(world=world, scenario=scenario, seed=seed, length=length)
    runs = {"adaptive": True, "baseline": False} if compare else {"": adapt}
    results = {}
    shared_prior = prior
    with _progress_bar() as bar:
        for name, adaptive in runs.items():
            task = bar.add_task(name or "inspection", total=1.0)

            def show(label: str, share: float, task=task, name=name) -> None:
                bar.update(task, completed=share, description=f"{name} {label}".strip())

            config = base.model_copy(update={"adapt": adaptive})
            run_dir = out / name if name else out
            result = run_routine(
                config, run_dir, prior_path=shared_prior, tasks_path=tasks, progress=show
            )
            results[name] = result
            if shared_prior is None and (run_dir / PRIOR_FILE).exists():
                shared_prior = run_dir / PRIOR_FILE  # the baseline plans on the same M_H
            if result.state != "completed":
                break
    if pictures:
        for result in results.values():
            render_routine(result.run_dir)
        if compare and len(results) == len(runs):
            figure = comparison_figure({n: r.run_dir for n, r in results.items()})
            save_figure(figure, out / "comparison.png")
    for name, result in results.items():
        _print_result(name, result)
    if any(r.state == "interrupted" for r in results.values()):
        err_console.print(f"interrupted; partial results in {out}", highlight=False)
        raise typer.Exit(130)


def _print_result(name: str, result) -> None:
    m = result.metrics
    label = f"{name}: " if name else ""
    console.print(f"[bold]{label}{result.state}[/]: {result.reason}")
    if not m:
        return
    console.print(
        f"  tasks {m['tasks_completed']}/{m['tasks_total']}, utility "
        f"{_num(m['viewpoint_utility_mean'])}, viewing-distance MAE "
        f"{_num(m['view_distance_mae_m'])} m, ROI coverage {_num(m['roi_coverage_pct'], 1)} %, "
        f"max Γ_s {_num(m['gamma_s_max'])}, collisions {m['collisions']}"
    )
    console.print(f"  results: {result.run_dir} (summary.md, metrics.json, *.png)")


def _num(value: float | None, digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}"
