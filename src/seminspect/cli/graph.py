"""``seminspect graph``: inspect, query and export 3D Layered Semantic Graphs.

Every command takes a graph file written by ``seminspect mission`` (``graph.json`` in a run
directory) or the word ``example`` for the small graph shipped with the package.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.table import Table
from rich.tree import Tree

from seminspect.cli._common import console, writable_file

if TYPE_CHECKING:
    from seminspect.graphs.lsg.graph import LayeredSemanticGraph
    from seminspect.graphs.lsg.model import FeatureNode, LevelNode, PoseNode, TargetNode
    from seminspect.planning.hierarchical import RoutePlan

app = typer.Typer(no_args_is_help=True, add_completion=False)

PICTURE_SUFFIXES = (".png", ".svg", ".pdf")
GRAPH_HELP = "Graph JSON file, or 'example' for the graph shipped with seminspect."
EXAMPLE = "example"


def example_graph_path() -> Path:
    """Location of the example graph inside the installed package."""
    from seminspect.graphs.lsg.io import example_graph_path as shipped

    return shipped()


def _load(source: str) -> LayeredSemanticGraph:
    from seminspect.graphs.lsg.io import load_graph

    return load_graph(example_graph_path() if source == EXAMPLE else Path(source))


@app.command()
def info(graph_file: str = typer.Argument(..., metavar="FILE", help=GRAPH_HELP)) -> None:
    """Layer populations in the shape of 000 Table 3, and the targets."""
    graph = _load(graph_file)
    stats = graph.population()
    table = Table(title=f"3DLSG population: {graph_file}", title_justify="left")
    for column in ("Target", "Level", "Pose", "Feature", "Total", "Unified", "Reconciled (%)"):
        table.add_column(column, justify="right")
    table.add_row(
        str(stats.target),
        str(stats.level),
        str(stats.pose),
        str(stats.feature),
        str(stats.total),
        str(stats.unified),
        f"{stats.reconciled_pct:.1f}",
    )
    console.print(table)
    console.print("cells are nodes/edges summed over each layer's local graphs")
    targets = Table(title="Targets", title_justify="left")
    for column in ("name", "status", "levels", "poses", "features", "x", "y", "z"):
        targets.add_column(column, justify="left" if column in {"name", "status"} else "right")
    for target in graph.targets():
        poses = [p for level in target.levels for p in level.poses]
        features = sum(len(p.features) for p in poses)
        x, y, z = (f"{c:.2f}" for c in target.position)
        targets.add_row(
            target.id,
            target.status.value,
            str(len(target.levels)),
            str(len(poses)),
            str(features),
            x,
            y,
            z,
        )
    console.print(targets)


@app.command()
def tree(
    graph_file: str = typer.Argument(..., metavar="FILE", help=GRAPH_HELP),
    depth: int = typer.Option(
        4, "--depth", "-d", min=1, max=4, help="1 targets, 2 levels, 3 poses, 4 features."
    ),
    target: str | None = typer.Option(None, "--target", "-t", help="Show this target only."),
) -> None:
    """Print the hierarchy Target -> Level -> Pose -> Feature with each node's key attributes."""
    graph = _load(graph_file)
    targets = [graph.target(target)] if target else graph.targets()
    hierarchy = graph_tree(graph_file, targets, depth)
    # one node per line, however narrow the terminal: a line is something to grep
    wide = Console(file=console.file, markup=False, width=max(console.width, _widest(hierarchy)))
    wide.print(hierarchy)


def graph_tree(title: str, targets: list[TargetNode], depth: int) -> Tree:
    """The hierarchy under ``targets`` down to ``depth`` layers (1 = targets only)."""
    root = Tree(f"{title}: {_count(len(targets), 'target')}")
    for target in targets:
        branch = root.add(_target_line(target))
        for level in target.levels if depth > 1 else []:
            twig = branch.add(_level_line(level))
            for pose in level.poses if depth > 2 else []:
                leaf = twig.add(_pose_line(pose))
                for feature in pose.features if depth > 3 else []:
                    leaf.add(_feature_line(feature))
    return root


def _widest(node: Tree, indent: int = 0) -> int:
    """Columns the tree needs so that no label wraps (rich indents each level by 4)."""
    own = indent + len(str(node.label))
    return max([own, *(_widest(child, indent + 4) for child in node.children)])


def _target_line(target: TargetNode) -> str:
    return (
        f"{target.id}  {target.label}, {target.status.value}, "
        f"{_count(len(target.levels), 'level')}, {_xyz(target.position)}, "
        f"score {target.score:.2f}"
    )


def _level_line(level: LevelNode) -> str:
    return f"{level.name}  {_count(len(level.poses), 'pose')}, {_xyz(level.position)}"


def _pose_line(pose: PoseNode) -> str:
    image = f", {pose.image}" if pose.image else ""
    return (
        f"{pose.name}  {_xyz(pose.position)}, yaw {pose.yaw:.2f}, "
        f"{_count(len(pose.features), 'feature')}{image}"
    )


def _feature_line(feature: FeatureNode) -> str:
    return f"{feature.name}  {feature.label}, score {feature.score:.2f}, {_xyz(feature.position)}"


def _xyz(position: Iterable[float]) -> str:
    x, y, z = (float(c) for c in position)
    return f"({x:.2f}, {y:.2f}, {z:.2f})"


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


@app.command()
def query(
    graph_file: str = typer.Argument(..., metavar="FILE", help=GRAPH_HELP),
    text: str = typer.Argument(
        ..., metavar="QUERY", help="e.g. 'Visit hood-1 in Level-0 of car-1'"
    ),
    start: tuple[float, float, float] | None = typer.Option(
        None, "--from", help="Start position X Y Z (default: the robot's position in the graph)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the answer as JSON."),
) -> None:
    """Plan a route for an operator query and print it layer by layer."""
    from seminspect.planning.hierarchical import HierarchicalPlanner

    graph = _load(graph_file)
    plan = HierarchicalPlanner(graph).query(text, start=start)
    if as_json:
        typer.echo(json.dumps(plan_summary(plan), indent=2))
    else:
        _print_plan(plan)


def plan_summary(plan: RoutePlan) -> dict[str, object]:
    """A JSON-ready description of a plan."""
    return {
        "query": plan.query,
        "goal": plan.goal_id,
        "observe": plan.terminal_id,
        "localisation": {
            "target": plan.localisation.target_id,
            "level": plan.localisation.level_id,
            "pose": plan.localisation.pose_id,
            "distance_m": plan.localisation.distance,
        },
        "target_route": list(plan.target_route),
        "level_route": list(plan.level_route),
        "pose_route": list(plan.pose_route),
        "waypoints": plan.waypoints.round(3).tolist(),
        "length_m": plan.length,
        "target_layer_length_m": plan.target_layer_length,
        "final_yaw_rad": plan.final_yaw,
        "planning_time_s": {
            "total": plan.timing.total_s,
            "localise": plan.timing.localise_s,
            "target_layer": plan.timing.target_layer_s,
            "local_layers": plan.timing.local_layers_s,
        },
        "nodes_settled": plan.settled,
    }


def _print_plan(plan: RoutePlan) -> None:
    loc = plan.localisation
    console.print(plan.query, style="bold")
    console.print(
        f"robot localised at {loc.node_id} ({loc.distance:.2f} m away): "
        f"target {loc.target_id}, level {loc.level_id.rsplit('/', 1)[-1]}"
    )
    console.print(
        f"Target layer: {' -> '.join(plan.target_route)} ({plan.target_layer_length:.2f} m)"
    )
    console.print(f"Level layer:  {' -> '.join(_short(i) for i in plan.level_route) or '-'}")
    console.print(f"Pose layer:   {' -> '.join(_short(i) for i in plan.pose_route) or '-'}")
    if plan.terminal_id:
        console.print(f"then observe {plan.terminal_id}")
    console.print(f"waypoints ({len(plan.waypoints)}):")
    for point in plan.waypoints:
        console.print(f"  {point[0]:9.2f} {point[1]:9.2f} {point[2]:7.2f}")
    timing = plan.timing
    console.print(
        f"path length {plan.length:.2f} m; planning time {timing.total_s * 1e6:.0f} µs "
        f"(target layer {timing.target_layer_s * 1e6:.0f} µs, "
        f"level+pose layers {timing.local_layers_s * 1e6:.0f} µs, {plan.settled} nodes settled)"
    )


def _short(node_id: str) -> str:
    """``car-1/Level-0/pose-3`` -> ``car-1:pose-3``."""
    parts = node_id.split("/")
    return f"{parts[0]}:{parts[-1]}"


class ExportFormat(str, Enum):
    graphml = "graphml"
    json = "json"
    spark_dsg = "spark-dsg"
    csv = "csv"


_SUFFIX = {
    ExportFormat.graphml: ".graphml",
    ExportFormat.json: ".json",
    ExportFormat.spark_dsg: ".dsg.json",
    ExportFormat.csv: "_csv",
}


@app.command()
def export(
    graph_file: str = typer.Argument(..., metavar="FILE", help=GRAPH_HELP),
    fmt: ExportFormat = typer.Option(ExportFormat.graphml, "--format", "-f", help="Output format."),
    out: Path | None = typer.Option(
        None,
        "--out",
        "-o",
        help="Output file, or folder for csv (default: beside FILE).",
    ),
) -> None:
    """Write the graph as GraphML, seminspect JSON, a spark-dsg scene graph or CSV tables
    (targets, levels, poses, features and each layer's edges; columns in docs/scene-graph.md)."""
    from seminspect.graphs.lsg.io import export_graphml, export_spark_dsg, save_graph
    from seminspect.graphs.lsg.tables import export_csv

    source = Path("example_graph.json") if graph_file == EXAMPLE else Path(graph_file)
    target = out or source.with_name(source.stem + _SUFFIX[fmt])
    if fmt is not ExportFormat.csv:
        writable_file(target)
    if target.resolve() == source.resolve():
        raise typer.BadParameter("the output would overwrite the input; pass --out")
    graph = _load(graph_file)
    if fmt is ExportFormat.csv:
        written = export_csv(graph, target)
        console.print(f"wrote {len(written)} tables to {target}")
        return
    writer = {
        ExportFormat.graphml: export_graphml,
        ExportFormat.json: save_graph,
        ExportFormat.spark_dsg: export_spark_dsg,
    }[fmt]
    writer(graph, target)
    console.print(f"wrote {target}")


@app.command()
def show(
    graph_file: str = typer.Argument(..., metavar="FILE", help=GRAPH_HELP),
    out: Path = typer.Option(
        Path("graph.png"), "--out", "-o", help="Picture to write (png, svg, pdf)."
    ),
    query_text: str | None = typer.Option(
        None, "--query", "-q", help="Also draw this query's route."
    ),
) -> None:
    """Draw the graph's layers stacked above the ground, optionally with a query's route."""
    from seminspect.planning.hierarchical import HierarchicalPlanner
    from seminspect.report.figures import save_figure
    from seminspect.report.lsg import draw_layers

    writable_file(out, PICTURE_SUFFIXES)
    graph = _load(graph_file)
    plan = HierarchicalPlanner(graph).query(query_text) if query_text else None
    save_figure(draw_layers(graph, plan=plan, title=query_text), out)
    console.print(f"wrote {out}")
