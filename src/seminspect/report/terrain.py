"""Pictures of terrain scene graphs, after 001 Figs 1, 3, 4b and 6.

- :func:`plot_classified_cloud`: the cloud from above, coloured by prompt (Figs 4b, 6a);
- :func:`plot_gvd_stages`: grid, distance map, pruned GVD with initial nodes, final GVD (Fig 3);
- :func:`plot_place_layer`: place nodes and links by terrain over the layer-1 points (Fig 6b);
- :func:`plot_layered_graph`: the layers stacked in 3D, joined by their edges (Fig 1).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from pathlib import Path

import matplotlib as mpl

mpl.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection
from numpy.typing import NDArray

from seminspect.core.io import atomic_write_with
from seminspect.core.rng import make_rng
from seminspect.graphs.terrain.gvd import GvdResult
from seminspect.graphs.terrain.prompting import UNCLASSIFIED, TaskPrompts
from seminspect.graphs.terrain.scene_graph import TerrainBuild

#: 001's colours: sidewalk magenta, grass green, asphalt blue, trees orange, cars cyan.
PAPER_COLOURS = {
    "sidewalk": "#d020d0",
    "grass": "#2ca02c",
    "asphalt": "#1f4fd0",
    "image of a tree": "#ff8c00",
    "image of a car": "#00c0d0",
}
_SPARE = ("#8c564b", "#bcbd22", "#9467bd", "#e377c2", "#17becf", "#7f7f7f", "#d62728")
UNCLASSIFIED_COLOUR = "#b0b0b0"


def prompt_colours(prompts: TaskPrompts) -> dict[str, str]:
    """A colour per prompt: 001's where the prompt is one of the paper's, else a spare one."""
    spare = iter(_SPARE * 4)
    return {p: PAPER_COLOURS.get(p) or next(spare) for p in prompts.all}


def _save(fig: Figure, path: str | Path) -> Path:
    try:
        return atomic_write_with(path, lambda buf: fig.savefig(buf, format="png", dpi=110))
    finally:
        plt.close(fig)


def subsample_rows(n: int, limit: int, seed: int) -> NDArray[np.int64]:
    """At most ``limit`` sorted row indices of ``n``, drawn without replacement from ``seed``."""
    if n <= limit:
        return np.arange(n)
    return np.sort(make_rng(seed, "report", "subsample").choice(n, limit, replace=False))


def plot_classified_cloud(
    path: str | Path,
    points: NDArray[np.float64],
    classes: NDArray[np.int64],
    prompts: TaskPrompts,
    *,
    max_points: int = 250_000,
    seed: int = 0,
) -> Path:
    """The whole cloud from above; prompted points in their prompt's colour, the rest grey."""
    rows = subsample_rows(points.shape[0], max_points, seed)
    colours = prompt_colours(prompts)
    fig, ax = plt.subplots(figsize=(9, 8))
    grey = rows[classes[rows] == UNCLASSIFIED]
    ax.scatter(points[grey, 0], points[grey, 1], s=0.3, c=UNCLASSIFIED_COLOUR, linewidths=0)
    for index, prompt in enumerate(prompts.all):
        mine = rows[classes[rows] == index]
        ax.scatter(
            points[mine, 0], points[mine, 1], s=0.5, c=colours[prompt], linewidths=0, label=prompt
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Prompted metric-semantic cloud (grey: no prompt matched)")
    ax.legend(markerscale=12, loc="upper right", fontsize=8)
    return _save(fig, path)


def _draw_nodes_and_links(ax, gvd: GvdResult, nodes: NDArray[np.int64], links: bool) -> None:
    if links and gvd.edges:
        ends = np.array([(a, b) for a, b, _ in gvd.edges])
        # (col, row) pairs in one collection: a plot call per link took seconds at thousands
        segments = gvd.nodes[ends][:, :, ::-1].astype(float)
        ax.add_collection(LineCollection(segments, colors="#20c020", linewidths=1.2))
    ax.scatter(nodes[:, 1], nodes[:, 0], s=14, c="red", zorder=3)


def plot_gvd_stages(path: str | Path, gvd: GvdResult, terrain: str) -> Path:
    """001 Fig 3 for one terrain: (a) grid, (b) distance map, (c) pruned GVD, (d) final GVD."""
    fig, axes = plt.subplots(1, 4, figsize=(18, 5))
    axes[0].imshow(gvd.occupancy, cmap="gray", origin="lower", interpolation="nearest")
    axes[0].contour(gvd.cleaned, levels=[0.5], colors="orange", linewidths=0.7, origin="lower")
    axes[0].set_title(f"(a) {terrain} grid (orange: after dilation/erosion)")
    axes[1].imshow(gvd.distance, cmap="gray", origin="lower", interpolation="nearest")
    axes[1].set_title("(b) brushfire distance map")
    for ax, nodes, links, title in (
        (axes[2], gvd.initial_nodes, False, f"(c) pruned GVD, {len(gvd.initial_nodes)} nodes"),
        (axes[3], gvd.nodes, True, f"(d) final: {len(gvd.nodes)} nodes, {len(gvd.edges)} edges"),
    ):
        ax.imshow(gvd.cleaned, cmap="gray", origin="lower", interpolation="nearest", alpha=0.35)
        skeleton = np.ma.masked_where(~gvd.skeleton, gvd.skeleton)
        ax.imshow(skeleton, cmap="autumn_r", origin="lower", interpolation="nearest")
        _draw_nodes_and_links(ax, gvd, nodes, links)
        ax.set_title(title)
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    return _save(fig, path)


def plot_place_layer(path: str | Path, build: TerrainBuild, max_points: int = 150_000) -> Path:
    """001 Fig 6b: places and their links, coloured by terrain, over the layer-1 points."""
    scene = build.scene
    colours = prompt_colours(scene.prompts)
    layer = scene.layer1
    fig, ax = plt.subplots(figsize=(9, 8))
    if layer is not None:
        rows = subsample_rows(layer.points.shape[0], max_points, 1)
        tint = [colours[scene.prompts.all[c]] for c in layer.classes[rows]]
        ax.scatter(layer.points[rows, 0], layer.points[rows, 1], s=0.3, c=tint, alpha=0.25)
    graph = scene.graph
    # one collection per line style: a plot call per link took seconds at thousands of places
    for kind, style in (("gvd", "solid"), ("traversable", "dotted")):
        segments = [
            (graph.nodes[a]["position"][:2], graph.nodes[b]["position"][:2])
            for a, b, data in graph.edges(data=True)
            if data["kind"] == kind
        ]
        if segments:
            ax.add_collection(
                LineCollection(segments, colors="black", linewidths=0.8, linestyles=style)
            )
    ax.autoscale_view()
    for terrain in scene.prompts.terrain:
        mine = [n for n in scene.nodes_of("place") if graph.nodes[n]["terrain"] == terrain]
        xy = np.array([graph.nodes[n]["position"][:2] for n in mine]).reshape(-1, 2)
        ax.scatter(xy[:, 0], xy[:, 1], s=28, c=colours[terrain], edgecolors="black", label=terrain)
    ax.set_aspect("equal")
    ax.set_title("Terrain-aware place nodes (dotted: links between terrain types)")
    ax.legend(loc="upper right", fontsize=8)
    return _save(fig, path)


def _box_segments(low: NDArray, high: NDArray, lift: float) -> list[NDArray]:
    """The 12 edges of an axis-aligned box, lifted by ``lift``."""
    corners = np.array([[x, y, z + lift] for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])])  # fmt: skip
    # corners differing in one coordinate share an edge
    return [
        corners[[i, j]] for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1
    ]


def layer_lifts(span: float) -> dict[int, float]:
    """Height each of layers 2-5 is drawn above the points, as a share of the map's width."""
    return {layer: 0.12 * (layer - 1) * span for layer in (2, 3, 4, 5)}


def plot_layered_graph(path: str | Path, build: TerrainBuild, max_points: int = 60_000) -> Path:
    """001 Fig 1: layer 1 points at the bottom, then objects, places, regions and the root."""
    scene, graph = build.scene, build.scene.graph
    colours = prompt_colours(scene.prompts)
    fig = plt.figure(figsize=(11, 9))
    ax = fig.add_subplot(projection="3d")
    span = 1.0
    if scene.layer1 is not None and scene.layer1.points.shape[0]:
        pts = scene.layer1.points
        span = float(np.ptp(pts[:, :2], axis=0).max()) or 1.0
        rows = subsample_rows(pts.shape[0], max_points, 2)
        n_terrain = len(scene.prompts.terrain)
        # 001 Fig 1: objects black, terrain types in shades of grey
        shade = np.where(
            scene.layer1.classes[rows] >= n_terrain,
            0.0,
            0.3 + 0.5 * scene.layer1.classes[rows] / max(n_terrain, 1),
        )
        ax.scatter(
            pts[rows, 0], pts[rows, 1], pts[rows, 2], s=0.2, c=shade, cmap="gray", vmin=0, vmax=1
        )
    lift = layer_lifts(span)

    def at(node: str) -> NDArray[np.float64]:
        data = graph.nodes[node]
        return data["position"] + np.array([0.0, 0.0, lift[data["layer"]]])

    _draw_graph(ax, graph, at, colours, lift[2])
    ax.set_title("Layers: 1 points, 2 objects, 3 places, 4 regions, 5 map")
    ax.set_axis_off()
    ax.view_init(elev=22, azim=-60)
    return _save(fig, path)


def _draw_graph(ax, graph, at: Callable[[str], NDArray], colours: dict[str, str], lift: float):
    """Layers 2-5 as one line collection per colour and one scatter per marker kind (a plot
    call per edge and node took minutes at 10k places)."""
    lines: dict[tuple[str, float, float], list[NDArray]] = defaultdict(list)
    for a, b, data in graph.edges(data=True):
        if data["kind"] in ("gvd", "traversable"):
            key = (colours[graph.nodes[a]["terrain"]], 0.8, 1.0)
        else:
            key = ("#606060", 0.3, 0.5)
        lines[key].append(np.stack([at(a), at(b)]))
    markers: dict[tuple[str, str, float], list[NDArray]] = defaultdict(list)
    for node, data in graph.nodes(data=True):
        if data["kind"] == "object":
            box = _box_segments(data["bbox_min"], data["bbox_max"], lift)
            lines[(colours[data["label"]], 1.0, 1.0)] += box
        elif data["kind"] == "place":
            markers[("o", colours[data["terrain"]], 12.0)].append(at(node))
        elif data["kind"] == "region":
            markers[("^", "#ffd700", 60.0)].append(at(node))
        else:
            markers[("*", "black", 120.0)].append(at(node))
    for (colour, width, alpha), segments in lines.items():
        ax.add_collection3d(
            Line3DCollection(segments, colors=colour, linewidths=width, alpha=alpha)
        )
    for (marker, colour, size), points in markers.items():
        edge = "black" if marker == "^" else "face"
        ax.scatter(
            *np.array(points).T, s=size, marker=marker, c=colour, edgecolors=edge, depthshade=False
        )
