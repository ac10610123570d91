"""``seminspect world``: list, draw and export the built-in simulated worlds and user worlds."""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.table import Table
from rich.text import Text

from seminspect.cli._common import console, writable_directory, writable_file

if TYPE_CHECKING:
    from seminspect.worlds import World

app = typer.Typer(no_args_is_help=True, add_completion=False)


class View(str, Enum):
    top = "top"
    three_d = "3d"
    both = "both"


NAME_HELP = "World name, e.g. city, or a user world folder (mesh + labels file)."
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
        size = info.bbox_max - info.bbox_min
        table.add_row(
            info.name,
            info.class_name,
            f"{info.centroid[0]:.1f}",
            f"{info.centroid[1]:.1f}",
            f"{size[0]:.1f}",
            f"{size[1]:.1f}",
            f"{info.height:.1f}",
            str(len(info.parts)),
        )
    console.print(table)
    console.print(f"wrote {target}", soft_wrap=True)


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
