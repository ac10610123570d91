"""``seminspect world``: list, draw, check and export the built-in worlds and user worlds."""

from __future__ import annotations

import warnings
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.table import Table
from rich.text import Text

from seminspect.cli._common import console, labelled, writable_directory, writable_file

if TYPE_CHECKING:
    from seminspect.worlds import InstanceInfo, World
    from seminspect.worlds.site_check import Finding

app = typer.Typer(no_args_is_help=True, add_completion=False)


class View(str, Enum):
    top = "top"
    three_d = "3d"
    both = "both"


NAME_HELP = (
    "World name, e.g. city, or a user world: a site file, an SDF world or model, or a folder "
    "with a mesh and its labels file."
)
SCENARIO_HELP = "Scenario of the world (its default when omitted; see 'seminspect world list')."
SEED_HELP = "Seed of every random choice; the same seed gives the same world."


def _generate(name: str, scenario: str | None, seed: int) -> World:
    from seminspect.worlds import open_world

    return open_world(name, scenario, seed)


@app.command("list")
def list_worlds() -> None:
    """The built-in worlds, their scenarios and what they contain."""
    from seminspect.worlds import available_worlds

    table = Table(title="Built-in worlds", title_justify="left")
    for column in ("name", "scenarios (default first)", "description"):
        table.add_column(column)
    for spec in available_worlds():
        others = [s for s in spec.scenarios if s != spec.default_scenario]
        table.add_row(spec.name, ", ".join([spec.default_scenario, *others]), spec.description)
    console.print(table)


@app.command()
def show(
    name: str = typer.Argument(..., help=NAME_HELP),
    scenario: str = typer.Option(None, "--scenario", "-s", help=SCENARIO_HELP),
    seed: int = typer.Option(0, "--seed", min=0, help=SEED_HELP),
    out: Path = typer.Option(None, "--out", "-o", help="PNG to write (default: NAME.png)."),
    view: View = typer.Option(View.both, "--view", help="Top-down map, 3D view or both."),
) -> None:
    """Draw a world: a labelled top-down map and a 3D view, and list its objects."""
    from seminspect.report.worlds import save_world_picture

    target = writable_file(out or Path(f"{Path(name).stem}.png"), (".png",))
    world = _generate(name, scenario, seed)
    with console.status(Text(f"drawing {name}")):  # a spinner reads markup from plain str
        save_world_picture(world, target, view.value)
    kind = world.metadata.get("scenario", "user world")
    table = Table(title=f"{name} ({kind}), seed {seed}", title_justify="left")
    for column in ("object", "class", "x", "y", "length", "width", "height", "parts"):
        table.add_column(column, justify="left" if column in {"object", "class"} else "right")
    for info in world.instances.values():
        length, width = _size(world, info)
        table.add_row(
            info.name,
            info.class_name,
            f"{info.centroid[0]:.1f}",
            f"{info.centroid[1]:.1f}",
            f"{length:.1f}",
            f"{width:.1f}",
            f"{info.height:.1f}",
            str(len(info.parts)),
        )
    console.print(table)
    console.print(f"wrote {target}", soft_wrap=True)


def _size(world: World, info: InstanceInfo) -> tuple[float, float]:
    """(length, width): along and across the heading a site gives an object, else along x
    and y."""
    from seminspect.worlds.pieces import heading_of, size_along

    heading = heading_of(world, info.name)
    if heading is not None:
        return size_along(world, info, heading)
    size = info.bbox_max - info.bbox_min
    return float(size[0]), float(size[1])


@app.command()
def check(
    file: Path = typer.Argument(..., help="Site file, SDF world or model, or user world folder."),
    classes: str = typer.Option(
        None,
        "--classes",
        help="Comma-separated classes a mission would inspect (default: the mission's).",
    ),
) -> None:
    """Say what is missing or odd in a site before any mission; exit 1 on any error."""
    from seminspect.worlds.site import is_site_file, missing_files
    from seminspect.worlds.site_check import ROBOT_RADIUS, Finding, check_world

    missing = missing_files(file) if is_site_file(file) else []
    if missing:
        _print_findings([Finding("error", line) for line in missing], file)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        world = _generate(str(file), None, 0)
    findings = [Finding("warning", str(w.message)) for w in caught if _is_users(w.category)]
    findings += check_world(world, _target_classes(str(file), classes))
    table = Table(title=f"{file}: {world.name}", title_justify="left")
    for column in ("object", "class", "length", "width", "height", "heading", "parts"):
        table.add_column(
            column, justify="left" if column in {"object", "class", "parts"} else "right"
        )
    for info in world.instances.values():
        length, width = _size(world, info)
        heading = _heading(world, info.name)
        sizes = (f"{length:.1f}", f"{width:.1f}", f"{info.height:.1f}")
        table.add_row(info.name, info.class_name, *sizes, heading, ", ".join(info.parts) or "-")
    console.print(table)
    start = ", ".join(f"{v:.1f}" for v in world.start_position)
    console.print(f"start ({start}), robot radius {ROBOT_RADIUS:g} m", soft_wrap=True)
    _print_findings(findings, file)


def _target_classes(name: str, classes: str | None) -> list[str]:
    """The classes given, else those a mission on ``name`` inspects by default."""
    from seminspect.missions.xflie.config import VEHICLE_CLASSES, WORLD_DEFAULTS

    if classes:
        return [c.strip() for c in classes.split(",") if c.strip()]
    return list(WORLD_DEFAULTS.get(name, {}).get("classes", VEHICLE_CLASSES))


def _is_users(category: type[Warning]) -> bool:
    """Warnings about the user's files (not a library's deprecation notices)."""
    return issubclass(category, UserWarning)


def _heading(world: World, name: str) -> str:
    import math

    from seminspect.worlds.pieces import heading_of

    heading = heading_of(world, name)
    return "-" if heading is None else f"{round(math.degrees(heading))} deg"


def _print_findings(findings: list[Finding], file: Path) -> None:
    """One line per finding, a last line counting them; exit 1 when one is an error."""
    styles = {"error": "red", "warning": "yellow"}
    for finding in findings:
        label = f"{finding.level}:"
        console.print(labelled(label, styles[finding.level], finding.message), soft_wrap=True)
    errors = sum(f.level == "error" for f in findings)
    warned = len(findings) - errors
    if errors:
        console.print(f"{file}: {errors} error(s), {warned} warning(s)", soft_wrap=True)
        raise typer.Exit(1)
    console.print(f"{file}: ready ({warned} warning(s))", soft_wrap=True)


@app.command()
def export(
    name: str = typer.Argument(..., help=NAME_HELP),
    out: Path = typer.Option(..., "--out", "-o", help="Directory for world.ply and labels.json."),
    scenario: str = typer.Option(None, "--scenario", "-s", help=SCENARIO_HELP),
    seed: int = typer.Option(0, "--seed", min=0, help=SEED_HELP),
) -> None:
    """Write a world as a mesh plus labels file that 'load_world' (and other tools) can read."""
    from seminspect.worlds import save_world

    writable_directory(out)
    world = _generate(name, scenario, seed)
    save_world(world, out)
    summary = world.summary()
    console.print(
        f"wrote {out / 'world.ply'} and {out / 'labels.json'}: {summary['faces']} faces, "
        f"objects {summary['objects']}",
        soft_wrap=True,
    )
