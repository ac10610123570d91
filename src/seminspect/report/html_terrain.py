"""``report.html`` of a terrain graph directory: layers 1-5 of 001 Fig 1 in 3D, summary tables.

Layer 1's task points (a seeded sample of at most :data:`MAX_TERRAIN_POINTS`), then objects,
places, regions and the map root, lifted as in 001 Fig 1 and coloured by prompt.
"""

from __future__ import annotations

import html
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.core.io import read_json
from seminspect.graphs.terrain.io import load_terrain_graph
from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph
from seminspect.report.html_page import (
    REPORT_FILE,
    Section,
    key_value_table,
    node_trace,
    scene_layout,
    segments_trace,
    write_page,
)
from seminspect.report.terrain import layer_lifts, prompt_colours, subsample_rows

#: Layer-1 points drawn in a terrain report (the page stays a few MB).
MAX_TERRAIN_POINTS = 20_000

_TERRAIN_LAYERS = {2: "Objects", 3: "Places", 4: "Regions", 5: "Map"}
#: Edges within the place layer; every other kind joins two layers.
_PLACE_EDGES = ("gvd", "traversable")


def write_terrain_report(run_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a terrain graph directory: layers 1-5 of 001 Fig 1, summary tables."""
    root = Path(run_dir)
    scene = load_terrain_graph(root / "graph.json")
    summary_file = root / "summary.json"
    sections = [Section("Graph", key_value_table(scene.summary()))]
    if summary_file.is_file():
        sections.append(Section("Run", key_value_table(read_json(summary_file))))
    figures = [("scene", terrain_scene_figure(scene))]
    title = f"Terrain scene graph {root.name}"
    return write_page(root / REPORT_FILE, title, figures, sections, {})


def terrain_scene_figure(scene: TerrainSceneGraph):
    """001 Fig 1 in 3D: layer-1 points, then objects, places, regions and the map root."""
    graph = scene.graph
    colours = prompt_colours(scene.prompts)
    positions = np.array([graph.nodes[n]["position"] for n in graph.nodes]).reshape(-1, 3)
    span = float(np.ptp(positions[:, :2], axis=0).max()) if len(positions) > 1 else 1.0
    figure = go.Figure()
    if scene.layer1 is not None and len(scene.layer1.points):
        figure.add_trace(_layer1_trace(scene, colours))
        span = float(np.ptp(scene.layer1.points[:, :2], axis=0).max()) or span
    lift = layer_lifts(span or 1.0)

    def at(node: str) -> NDArray[np.float64]:
        data = graph.nodes[node]
        return np.asarray(data["position"], dtype=float) + np.array([0, 0, lift[data["layer"]]])

    edges = list(graph.edges(data=True))
    place_links = [(at(a), at(b)) for a, b, d in edges if d["kind"] in _PLACE_EDGES]
    hierarchy = [(at(a), at(b)) for a, b, d in edges if d["kind"] not in _PLACE_EDGES]
    figure.add_trace(segments_trace(place_links, "place edges", "#444444", "solid"))
    figure.add_trace(segments_trace(hierarchy, "layer edges", "#aaaaaa", "dot"))
    for layer, name in _TERRAIN_LAYERS.items():
        nodes = [n for n, d in graph.nodes(data=True) if d["layer"] == layer]
        xyz = np.array([at(n) for n in nodes]).reshape(-1, 3)
        node_colours = [_terrain_colour(graph.nodes[n], colours) for n in nodes]
        hover = [_terrain_hover(n, graph.nodes[n]) for n in nodes]
        figure.add_trace(node_trace(xyz, name, node_colours, hover, [""] * len(nodes)))
    scene_layout(figure, "Terrain scene graph, layers 1-5 (click a legend entry to toggle)")
    return figure


def _layer1_trace(scene: TerrainSceneGraph, colours: Mapping[str, str]):
    layer1 = scene.layer1
    assert layer1 is not None
    rows = subsample_rows(len(layer1.points), MAX_TERRAIN_POINTS, 0)
    names = [scene.prompts.all[c] for c in layer1.classes[rows]]
    return go.Scatter3d(
        x=layer1.points[rows, 0], y=layer1.points[rows, 1], z=layer1.points[rows, 2],
        mode="markers", name=f"Points (layer 1, {len(rows)} of {len(layer1.points)})",
        marker={"size": 1.5, "color": [colours[n] for n in names]}, hovertext=names,
        hoverinfo="text", meta={"layer": "Points", "nodes": len(rows)},
    )  # fmt: skip


def _terrain_colour(data: Mapping[str, Any], colours: Mapping[str, str]) -> str:
    if data["kind"] == "object":
        return colours.get(data.get("label") or "", "#000000")
    if data["kind"] == "place":
        return colours.get(data.get("terrain") or "", "#000000")
    return "#ffd700" if data["kind"] == "region" else "#000000"


def _terrain_hover(node: str, data: Mapping[str, Any]) -> str:
    lines = [f"<b>{html.escape(node)}</b>", f"layer {data['layer']}: {data['kind']}"]
    for key in ("label", "terrain", "score", "points", "clearance", "area", "members"):
        value = data.get(key)
        if value is not None:
            shown = f"{value:.2f}" if isinstance(value, float) else html.escape(str(value))
            lines.append(f"{key}: {shown}")
    return "<br>".join(lines)
