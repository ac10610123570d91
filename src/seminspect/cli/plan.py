"""``seminspect plan``: a volumetric path between two points on a map file."""

from __future__ import annotations

from pathlib import Path

import typer

from seminspect.cli._common import console, writable_file

_HELP = """Plan a collision-free path on a map: .bt (OctoMap), a seminspect map .npz, or a
.ply/.pcd cloud (occupied cells only: add --through-unknown).


Start and goal are moved to the nearest free cell, onto one free component when they lie in
different ones; without them the path joins two far-apart points of the largest component."""


def _point(text: str | None, option: str):
    """``x,y,z`` as a float array (None stays None)."""
    import numpy as np

    from seminspect.core.errors import InvalidInputError

    if text is None:
        return None
    try:
        values = [float(part) for part in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3 or not np.all(np.isfinite(values)):
        raise InvalidInputError(f"{option} takes x,y,z in metres (e.g. 1.0,2.5,1.2), got {text!r}")
    return np.asarray(values)


def app(
    map_file: Path = typer.Argument(..., help="The map (.bt, .npz, .ply, .pcd)."),
    start: str | None = typer.Option(None, "--start", help="x,y,z [m]; default: chosen."),
    goal: str | None = typer.Option(None, "--goal", help="x,y,z [m]; default: chosen."),
    resolution: float | None = typer.Option(
        None, "--resolution", help="Cell size [m]; default: the map's (0.1 for a cloud).", min=0.01
    ),
    clearance: float = typer.Option(
        0.3,
        "--clearance",
        help="Distance kept from occupied cells [m] (the robot's radius).",
        min=0,
    ),
    snap: float = typer.Option(
        2.0, "--snap", help="How far start and goal may be moved onto free space [m].", min=0
    ),
    through_unknown: bool = typer.Option(
        False, "--through-unknown", help="Let the path cross unknown cells (at twice the cost)."
    ),
    out: Path | None = typer.Option(None, "--out", "-o", help="Write the path (.csv or .json)."),
    picture: Path | None = typer.Option(None, "--picture", help="Draw it top down (.png)."),
) -> None:
    from seminspect.planning.map_files import read_map_file
    from seminspect.planning.map_plan import PATH_SUFFIXES, plan_on_map, write_path

    ends = _point(start, "--start"), _point(goal, "--goal")
    for target, suffixes in ((out, PATH_SUFFIXES), (picture, (".png", ".svg", ".pdf"))):
        if target is not None:
            writable_file(target, suffixes)
    voxel_map = read_map_file(map_file, resolution)
    plan = plan_on_map(
        voxel_map, *ends, clearance=clearance, max_snap=snap, through_unknown=through_unknown
    )
    _print_plan(map_file, plan)
    if out is not None:
        console.print(f"path: {write_path(out, plan)}")
    if picture is not None:
        from seminspect.report.figures import save_figure
        from seminspect.report.map_plan import map_plan_figure

        console.print(f"picture: {save_figure(map_plan_figure(voxel_map, plan), picture)}")


def _print_plan(map_file: Path, plan) -> None:
    from seminspect.planning.gridmap import format_point

    chosen = " (chosen: two far-apart points of the largest free component)" if plan.chosen else ""
    console.print(
        f"{map_file}: {plan.free_cells} free cells of {plan.resolution:g} m keeping "
        f"{plan.clearance_m:g} m clear, in {plan.components} components{chosen}"
    )
    for name, snap in (("start", plan.start), ("goal", plan.goal)):
        moved = f", moved {snap.moved_m:.2f} m from {format_point(snap.requested)}"
        console.print(f"{name} {format_point(snap.point)}{moved if snap.moved_m > 0 else ''}")
    path = plan.path
    console.print(
        f"path: {path.length:.2f} m, {len(path.cells)} cells, {len(path.waypoints)} waypoints; "
        f"map {plan.build_s:.2f} s, search {plan.search_s:.3f} s"
    )
