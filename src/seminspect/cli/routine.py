"""``seminspect routine``: routine inspection on an outdated map (paper 002)."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from seminspect.cli._common import (
    console,
    existing_outputs,
    exit_stopped,
    labelled,
    open_live_view,
    progress_bar,
    view_options,
)

if TYPE_CHECKING:
    from seminspect.missions.routine.live import LiveWatch

app = typer.Typer(no_args_is_help=True, help="Routine inspection on an outdated map (002).")

_WORLD = typer.Option(
    "mine-drift",
    "--world",
    "-w",
    help="Site: mine-drift, or an OctoMap (.bt) whose voxels make the site and M_H.",
)
_SCENARIO = typer.Option(
    "nominal", "--scenario", "-s", help="nominal, receding, advancing or obstructed."
)
_SEED = typer.Option(0, "--seed", help="Seed of the site and the tour.", min=0)
_LENGTH = typer.Option(20.0, "--length", help="Drift length [m].", min=10, max=200)
_HISTORICAL = typer.Option(
    None,
    "--historical",
    help="Your own site as first mapped: a directory with world.<mesh> and labels.json "
    "(as 'seminspect world export' writes); replaces --world/--scenario.",
)
_CURRENT = typer.Option(
    None, "--current", help="Your own site as it is now (same layout as --historical)."
)
_VIEW, _VIEW_PORT = view_options("the inspection", " (one run: not with --compare)")


def _config_and_site(world, scenario, seed, length, historical, current, *, need_current=True):
    """The settings, and the user's site pair when --historical/--current are given."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.routine.config import RoutineConfig
    from seminspect.missions.routine.site_from_map import SITE_KIND, is_map_file, site_from_map
    from seminspect.worlds.routine_sites import user_site, world_files

    if is_map_file(world):
        if historical is not None or current is not None:
            raise InvalidInputError("--world MAP builds the site: leave out --historical/--current")
        config = RoutineConfig(world=SITE_KIND, scenario=SITE_KIND, seed=seed, length=length)
        return config, site_from_map(world, config)
    if historical is None and current is None:
        return RoutineConfig(world=world, scenario=scenario, seed=seed, length=length), None
    if historical is None or (need_current and current is None):
        raise InvalidInputError("--historical and --current go together")
    before = world_files(historical)
    site = user_site(before, world_files(current) if current is not None else before)
    return RoutineConfig(world="user", scenario="user", seed=seed, length=length), site


@app.command("map")
def map_command(
    world: str = _WORLD,
    scenario: str = _SCENARIO,
    seed: int = _SEED,
    length: float = _LENGTH,
    historical: Path | None = _HISTORICAL,
    out: Path = typer.Option(..., "--out", "-o", help="Directory for the map (map.npz)."),
) -> None:
    """Record M_H: a mapping traverse through the scenario's historical world."""
    from seminspect.missions.routine.run import map_site

    config, site = _config_and_site(
        world, scenario, seed, length, historical, None, need_current=False
    )
    with progress_bar() as bar:
        task = bar.add_task("mapping M_H", total=1.0)
        path = map_site(config, out, lambda share: bar.update(task, completed=share), site)
    console.print(f"M_H recorded: {path}")
    site_option = f"--world {world}" if config.world == "map" else f"--scenario {scenario}"
    console.print(f"inspect with: seminspect routine inspect {site_option} --prior {path}")


@app.command("inspect")
def inspect_command(
    world: str = _WORLD,
    scenario: str = _SCENARIO,
    seed: int = _SEED,
    length: float = _LENGTH,
    historical: Path | None = _HISTORICAL,
    current: Path | None = _CURRENT,
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
    view: bool = _VIEW,
    view_port: int = _VIEW_PORT,
) -> None:
    """Inspect the scenario's regions in the current world with a plan made on M_H."""
    from seminspect.missions.routine.run import PRIOR_FILE, run_routine
    from seminspect.report.figures import save_figure
    from seminspect.report.html import write_routine_comparison_report, write_routine_report
    from seminspect.report.routine import comparison_figure, render_routine

    if view and compare:
        from seminspect.core.errors import InvalidInputError

        raise InvalidInputError(
            "--view watches one run: leave out --compare (or watch --adapt and --no-adapt "
            "one at a time)"
        )
    base, site = _config_and_site(world, scenario, seed, length, historical, current)
    if prior is None and base.world == "map":
        prior = Path(world)  # the map is M_H too: nothing to record
    runs = {"adaptive": True, "baseline": False} if compare else {"": adapt}
    results = {}
    shared_prior = prior
    with _watched(view, view_port) as watch, progress_bar() as bar:
        for name, adaptive in runs.items():
            task = bar.add_task(name or "inspection", total=1.0)

            def show(label: str, share: float, task=task, name=name) -> None:
                bar.update(task, completed=share, description=f"{name} {label}".strip())

            config = base.model_copy(update={"adapt": adaptive})
            run_dir = out / name if name else out
            result = run_routine(
                config, run_dir, prior_path=shared_prior, tasks_path=tasks, progress=show,
                site=site, watch=watch,
            )  # fmt: skip
            results[name] = result
            if shared_prior is None and (run_dir / PRIOR_FILE).exists():
                shared_prior = run_dir / PRIOR_FILE  # the baseline plans on the same M_H
            if result.state != "completed":
                break
    if pictures and all(r.stop_signal != signal.SIGTERM for r in results.values()):
        for result in results.values():
            render_routine(result.run_dir)
            write_routine_report(result.run_dir)
        if compare and len(results) == len(runs):
            figure = comparison_figure({n: r.run_dir for n, r in results.items()})
            save_figure(figure, out / "comparison.png")
            write_routine_comparison_report(out)
    for name, result in results.items():
        _print_result(name, result)
    if compare and (out / "report.html").exists():
        console.print(f"compared: {out / 'report.html'}", soft_wrap=True)
    stopped = [r for r in results.values() if r.state == "interrupted"]
    if stopped:
        exit_stopped(stopped[0].stop_signal, out)


@contextmanager
def _watched(view: bool, port: int) -> Iterator[LiveWatch | None]:
    """The live view's watch for ``--view`` (None without it); its server closes after the run."""
    if not view:
        yield None
        return
    from seminspect.missions.routine.live import LiveWatch
    from seminspect.report.live_routine import RoutineFeed, routine_page

    with open_live_view(routine_page("seminspect routine inspect (live)"), port) as server:
        yield LiveWatch(RoutineFeed(server))


def _print_result(name: str, result) -> None:
    m = result.metrics
    label = f"{name}: " if name else ""
    console.print(labelled(f"{label}{result.state}:", "bold", result.reason))
    if not m:
        return
    console.print(
        f"  tasks {m.tasks_completed}/{m.tasks_total}, utility "
        f"{_num(m.viewpoint_utility_mean)}, viewing-distance MAE "
        f"{_num(m.view_distance_mae_m)} m, ROI coverage {_num(m.roi_coverage_pct, 1)} %, "
        f"max Γ_s {_num(m.gamma_s_max)}, collisions {m.collisions}"
    )
    # unwrapped: paths are copied from this line; it names only what the run holds
    outputs = ", ".join(existing_outputs(result.run_dir, _OUTPUTS))
    console.print(f"  results: {result.run_dir} ({outputs})", soft_wrap=True)


_OUTPUTS = ("report.html", "summary.md", "metrics.json")


def _num(value: float | None, digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}"
