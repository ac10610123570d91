"""``report.html`` of a mission run: the 3DLSG over the world, the trajectory, tables, plots.

The 3DLSG's Feature, Pose, Level and Target layers are stacked above the world's footprints
(000 Figs 2 and 12, the heights of ``graph.png``); hovering a node shows its name, label, score
and, where it has one, its view image. Below the scene, a time slider plays the mission back
(:mod:`~seminspect.report.html_playback`).
"""

from __future__ import annotations

import html
import os
from pathlib import Path
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import EdgeKind, FeatureNode, Node, RobotNode, TargetNode
from seminspect.missions.xflie.layout import load_run_world, read_metrics_document
from seminspect.report.html_page import (
    REPORT_FILE,
    Section,
    key_value_table,
    node_trace,
    rows_table,
    scene_layout,
    segments_trace,
    thumbnails,
    write_page,
)
from seminspect.report.html_playback import mission_playback, playback_section
from seminspect.report.lsg import LAYER_COLOURS, LAYER_ORDER, layer_heights, lifted_position
from seminspect.report.run_pictures import utility_series
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_trajectory
from seminspect.worlds import World


def write_mission_report(run_dir: str | os.PathLike[str], world: World | None = None) -> Path:
    """``report.html`` of a mission run: 3DLSG over the world, trajectory, tables, plots."""
    root = Path(run_dir)
    world = world if world is not None else load_run_world(root)
    graph = load_graph(root / "graph.json")
    trajectory = load_trajectory(root)
    images = thumbnails(root, _image_refs(graph))
    events = load_events(root)
    figures = [
        ("scene", mission_scene_figure(world, graph, trajectory)),
        ("utility", utility_plot(events)),
        ("path", path_plot(trajectory)),
    ]
    playback = mission_playback(graph, events, trajectory, images)
    replay = playback_section(playback, graph, footprint_trace(world))
    sections = ([replay] if replay is not None else []) + _metrics_sections(root)
    title = f"Mission run {root.name}"
    return write_page(root / REPORT_FILE, title, figures, sections, images)


def mission_scene_figure(world: World, graph: LayeredSemanticGraph, trajectory: NDArray):
    """The 3DLSG's layers stacked above the world's footprints, with the robot's path."""
    figure = go.Figure()
    figure.add_trace(footprint_trace(world))
    if len(trajectory):
        figure.add_trace(
            go.Scatter3d(
                x=trajectory[:, 1], y=trajectory[:, 2], z=trajectory[:, 3], mode="lines",
                name="trajectory", line={"color": "#1f77b4", "width": 3}, hoverinfo="skip",
            )
        )  # fmt: skip
    heights = layer_heights(graph)
    lifted = {node.id: lifted_position(node, heights) for node in graph.nodes()}
    for kind, style in ((EdgeKind.SPATIAL, "solid"), (EdgeKind.SYMBOLIC, "dot")):
        pairs = [(lifted[e.u], lifted[e.v]) for e in graph.edges() if e.kind is kind]
        figure.add_trace(segments_trace(pairs, f"{kind.value} edges", "#555555", style))
    for layer in LAYER_ORDER:
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        xyz = np.array([lifted[n.id] for n in nodes]).reshape(-1, 3)
        figure.add_trace(
            node_trace(
                xyz, layer.value.capitalize(), LAYER_COLOURS[layer],
                [node_hover(n) for n in nodes], [getattr(n, "image", None) or "" for n in nodes],
            )
        )  # fmt: skip
    robot = lifted[graph.robot.id]
    figure.add_trace(
        go.Scatter3d(
            x=[robot[0]], y=[robot[1]], z=[robot[2]], mode="markers", name="robot",
            marker={"symbol": "diamond", "size": 7, "color": "black"}, hovertext=["robot"],
            hoverinfo="text",
        )
    )  # fmt: skip
    scene_layout(figure, "3DLSG over the world (click a legend entry to toggle a layer)")
    return figure


def node_hover(node: Node) -> str:
    """A node's name, layer, label, score and status, as HTML for a hover box."""
    lines = [f"<b>{html.escape(node.id)}</b>", f"layer: {node.layer.value}"]
    if isinstance(node, TargetNode | FeatureNode):
        lines += [f"label: {html.escape(node.label)}", f"score: {node.score:.2f}"]
    if isinstance(node, TargetNode):
        lines.append(f"status: {node.status.value}")
    name = getattr(node, "name", None)
    if name and name != node.id:
        lines.append(f"name: {html.escape(name)}")
    return "<br>".join(lines)


def _image_refs(graph: LayeredSemanticGraph) -> set[str]:
    return {image for n in graph.nodes() if (image := getattr(n, "image", None))}


def footprint_lines(world: World) -> dict[str, list[float | None]]:
    """The outlines of the world's objects on the ground, one line with gaps (``None``)."""
    xs: list[float | None] = []
    ys: list[float | None] = []
    for info in world.instances.values():
        ring = np.asarray(info.footprint.exterior.coords)
        xs += [*ring[:, 0].tolist(), None]
        ys += [*ring[:, 1].tolist(), None]
    return {"x": xs, "y": ys}


def footprint_trace(world: World):
    """The world's footprints on the ground as one 3D line trace."""
    lines = footprint_lines(world)
    return go.Scatter3d(
        x=lines["x"], y=lines["y"], z=[None if x is None else 0.0 for x in lines["x"]],
        mode="lines", name="world", line={"color": "#999999", "width": 2}, hoverinfo="skip",
    )  # fmt: skip


def utility_plot(events: list[dict]):
    """Eq (6) for every candidate at every decision (000), the chosen one ringed."""
    series, chosen = utility_series(events)
    figure = go.Figure()
    for target, points in sorted(series.items()):
        data = np.array(points)
        figure.add_trace(go.Scatter(x=data[:, 0], y=data[:, 1], mode="lines+markers", name=target))
    if chosen:
        data = np.array(chosen)
        figure.add_trace(
            go.Scatter(
                x=data[:, 0], y=data[:, 1], mode="markers", name="selected (argmax)",
                marker={"size": 12, "color": "rgba(0,0,0,0)", "line": {"width": 2}},
            )
        )  # fmt: skip
    figure.update_layout(
        title="Target selection over time", xaxis_title="simulated time [s]",
        yaxis_title="utility U (eq 6)", height=420,
    )  # fmt: skip
    return figure


def path_plot(trajectory: NDArray):
    """The robot's true and odometry paths from above."""
    figure = go.Figure()
    if len(trajectory):
        for columns, name, dash in (((1, 2), "true", "solid"), ((5, 6), "odometry", "dash")):
            figure.add_trace(
                go.Scatter(
                    x=trajectory[:, columns[0]], y=trajectory[:, columns[1]], mode="lines",
                    name=f"path ({name})", line={"dash": dash}, text=trajectory[:, 0],
                    hovertemplate="t=%{text:.1f} s<br>x=%{x:.2f} y=%{y:.2f}",
                )
            )  # fmt: skip
    figure.update_layout(
        title="Trajectory from above", xaxis_title="x [m]", yaxis_title="y [m]", height=480,
        yaxis={"scaleanchor": "x"},
    )  # fmt: skip
    return figure


def _metrics_sections(root: Path) -> list[Section]:
    try:
        metrics = read_metrics_document(root)
    except FileFormatError:
        return [Section("Summary", "<p>This run wrote no metrics (it may have been stopped).</p>")]
    state = f"<p>State: <b>{html.escape(str(metrics.get('state')))}</b> "
    state += f"({html.escape(str(metrics.get('stop_reason', '')))})</p>"
    sections = [Section("Summary", state)]
    titles = {
        "table3": "3DLSG and inspection (000 Table 3 columns)",
        "table6": "Localisation and mapping (000 Table 6 columns)",
        "mission": "Mission",
    }
    sections += [Section(t, key_value_table(metrics[k])) for k, t in titles.items() if k in metrics]
    matches = metrics.get("targets", {}).get("matches", [])
    if matches:
        sections.append(Section("Targets and the site objects matched", _matches_table(matches)))
    return sections


def _matches_table(matches: list[dict[str, Any]]) -> str:
    """One row per graph target matched to a world object, by the world's own name."""
    rows = [
        (m["target_id"], m["truth"], m["horizontal_error"], m["error_3d"], m["inspected"])
        for m in matches
    ]
    headers = ("graph target", "site object", "horizontal error [m]", "3D error [m]", "inspected")
    return rows_table(headers, rows)
