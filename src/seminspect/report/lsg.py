"""Pictures of a 3DLSG: its layers stacked above the world, as in 000 Figs 2 and 12.

Each layer is drawn at its own height above the ground plane, so the hierarchy reads bottom to
top: the world's footprints, then Feature, Pose, Level and Target layers. Spatial edges are
solid; symbolic (parent-child) edges are thin dashed lines between layers.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import EdgeKind, Layer, Node, RobotNode
from seminspect.planning.hierarchical import RoutePlan
from seminspect.report.figures import new_figure

LAYER_STYLE = {
    Layer.FEATURE: ("tab:purple", 6, "Feature"),
    Layer.POSE: ("tab:orange", 8, "Pose"),
    Layer.LEVEL: ("tab:green", 28, "Level"),
    Layer.TARGET: ("tab:red", 60, "Target"),
}
LAYER_ORDER = (Layer.FEATURE, Layer.POSE, Layer.LEVEL, Layer.TARGET)
#: The same colours in hex, for the report's plotly figures (its scene and its playback).
LAYER_COLOURS = {
    Layer.FEATURE: "#9467bd",
    Layer.POSE: "#ff7f0e",
    Layer.LEVEL: "#2ca02c",
    Layer.TARGET: "#d62728",
}


def layer_heights(graph: LayeredSemanticGraph, spacing: float | None = None) -> dict[Layer, float]:
    """Drawing height of each layer: stacked above the tallest node, ``spacing`` apart."""
    top = max((float(n.position[2]) for n in graph.nodes()), default=0.0)
    span = spacing if spacing is not None else max(4.0, 0.06 * _extent(graph))
    return {layer: top + span * (1 + i) for i, layer in enumerate(LAYER_ORDER)}


def _extent(graph: LayeredSemanticGraph) -> float:
    points = np.array([n.position[:2] for n in graph.nodes()])
    return float(np.ptp(points, axis=0).max()) if len(points) > 1 else 10.0


def lifted_position(node: Node, heights: dict[Layer, float]) -> NDArray[np.float64]:
    """Where a node is drawn: at its layer's height (robot above the Target layer)."""
    x, y, z = node.position
    if isinstance(node, RobotNode):
        return np.array(
            [x, y, heights[Layer.TARGET] + 0.5 * (heights[Layer.TARGET] - heights[Layer.LEVEL])]
        )
    return np.array([x, y, heights[node.layer] + 0.15 * z])


def draw_layers(
    graph: LayeredSemanticGraph,
    footprints: Sequence[NDArray[np.float64]] = (),
    plan: RoutePlan | None = None,
    title: str | None = None,
) -> Figure:
    """A 3D figure of the stacked layers over optional world footprints (K x 2 polygons)."""
    heights = layer_heights(graph)
    figure = new_figure(11, 8)
    axes = figure.add_subplot(projection="3d")
    for outline in footprints:
        ring = np.vstack([outline, outline[:1]])
        axes.plot(ring[:, 0], ring[:, 1], 0.0, color="0.55", linewidth=0.8)
    lifted = {node.id: lifted_position(node, heights) for node in graph.nodes()}
    for edge in graph.edges():
        a, b = lifted[edge.u], lifted[edge.v]
        if edge.kind is EdgeKind.SPATIAL:
            axes.plot(*zip(a, b, strict=True), color="0.25", linewidth=0.7)
        else:
            axes.plot(*zip(a, b, strict=True), color="0.6", linewidth=0.3, linestyle=(0, (2, 3)))
    for layer in LAYER_ORDER:
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        if not nodes:
            continue
        colour, size, name = LAYER_STYLE[layer]
        xyz = np.array([lifted[n.id] for n in nodes])
        axes.scatter(
            xyz[:, 0],
            xyz[:, 1],
            xyz[:, 2],
            s=size,
            c=colour,
            label=f"{name} ({len(nodes)})",
            depthshade=False,
        )
    robot = lifted[graph.robot.id]
    axes.scatter(*robot, s=90, c="black", marker="^", label="robot", depthshade=False)
    for target in graph.targets():
        axes.text(
            *lifted[target.id],
            f" {target.id}",
            fontsize=7,
            color="tab:red" if target.inspected else "0.4",
        )
    if plan is not None:
        _draw_plan(axes, graph, plan, heights)
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_zticks([heights[layer] for layer in LAYER_ORDER])
    axes.set_zticklabels([LAYER_STYLE[layer][2] for layer in LAYER_ORDER])
    axes.view_init(elev=24, azim=-60)
    axes.legend(loc="upper left", fontsize=8)
    stats = graph.population()
    axes.set_title(title or f"3DLSG: {stats.unified.nodes} nodes, {stats.unified.edges} edges")
    figure.tight_layout()
    return figure


def _draw_plan(
    axes, graph: LayeredSemanticGraph, plan: RoutePlan, heights: dict[Layer, float]
) -> None:
    targets = [graph.node(t) for t in plan.target_route]
    lifted = np.array([lifted_position(t, heights) for t in targets])
    axes.plot(
        lifted[:, 0],
        lifted[:, 1],
        lifted[:, 2],
        color="tab:green",
        linewidth=2.5,
        label="global route",
    )
    local = np.array(
        [lifted_position(graph.node(n), heights) for n in plan.pose_route or plan.node_path]
    )
    if len(local):
        axes.plot(
            local[:, 0],
            local[:, 1],
            local[:, 2],
            color="tab:cyan",
            linewidth=2.0,
            label="local route",
        )
    ground = plan.waypoints
    axes.plot(
        ground[:, 0],
        ground[:, 1],
        np.zeros(len(ground)),
        color="gold",
        linewidth=1.8,
        label="metric path",
    )
