"""``report.html``: one self-contained page per run directory, drawn from the directory alone.

The page needs no network and no server: plotly.js is embedded inline, and the images a graph
refers to travel as small JPEG thumbnails inside the page. It shows

* the 3D scene graph layer by layer over the world (one legend entry per layer, so a click
  toggles it; hovering a node shows its name, label, score and, where it has one, its image),
  with the robot's trajectory;
* the run's summary tables and its plots.

Mission runs (``graph.json`` is a 3DLSG) and terrain runs (``graph.json`` is a terrain scene
graph) each get their own figure; :func:`write_report` tells them apart. Every layer trace
carries ``meta = {"layer": name, "nodes": count}`` so a reader (or a browser test) can check
the figure against the graph.
"""

from __future__ import annotations

import base64
import html
import json
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import atomic_write_text
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import FORMAT as LSG_FORMAT
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import EdgeKind, FeatureNode, Layer, Node, RobotNode, TargetNode
from seminspect.graphs.terrain.io import GRAPH_FORMAT as TERRAIN_FORMAT
from seminspect.graphs.terrain.io import load_terrain_graph
from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph
from seminspect.missions.xflie.layout import load_run_world, read_metrics_document
from seminspect.report.lsg import LAYER_ORDER, layer_heights, lifted_position
from seminspect.report.run_pictures import load_events, utility_series
from seminspect.report.terrain import layer_lifts, prompt_colours, subsample_rows
from seminspect.runs.trajectory import load_trajectory
from seminspect.worlds import World

REPORT_FILE = "report.html"
#: Thumbnails are this wide (pixels) and this JPEG quality: enough to recognise a view.
THUMBNAIL_WIDTH = 160
THUMBNAIL_QUALITY = 70
#: Layer-1 points drawn in a terrain report (the page stays a few MB).
MAX_TERRAIN_POINTS = 20_000

_LAYER_COLOURS = {
    Layer.FEATURE: "#9467bd",
    Layer.POSE: "#ff7f0e",
    Layer.LEVEL: "#2ca02c",
    Layer.TARGET: "#d62728",
}
_TERRAIN_LAYERS = {2: "Objects", 3: "Places", 4: "Regions", 5: "Map"}
#: Edges within the place layer; every other kind joins two layers.
_PLACE_EDGES = ("gvd", "traversable")


@dataclass(frozen=True)
class Section:
    """One titled block of the page (already HTML)."""

    title: str
    body: str


def write_report(run_dir: str | os.PathLike[str]) -> Path:
    """Write ``report.html`` for a mission or terrain run directory; returns its path."""
    root = Path(run_dir)
    graph_file = root / "graph.json"
    if not graph_file.is_file():
        raise InvalidInputError(f"{root} is not a run directory (no graph.json)")
    kind = _document_format(graph_file)
    if kind == LSG_FORMAT:
        return write_mission_report(root)
    if kind == TERRAIN_FORMAT:
        return write_terrain_report(root)
    raise FileFormatError(f"{graph_file}: neither a 3DLSG nor a terrain graph (format {kind!r})")


def _document_format(path: Path) -> str | None:
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"{path}: not readable JSON ({exc})") from None
    return document.get("format") if isinstance(document, dict) else None


# --- mission runs ------------------------------------------------------------------------------


def write_mission_report(run_dir: str | os.PathLike[str], world: World | None = None) -> Path:
    """``report.html`` of a mission run: 3DLSG over the world, trajectory, tables, plots."""
    root = Path(run_dir)
    world = world if world is not None else load_run_world(root)
    graph = load_graph(root / "graph.json")
    trajectory = load_trajectory(root)
    thumbnails = _thumbnails(root, _image_refs(graph))
    figures = [
        ("scene", mission_scene_figure(world, graph, trajectory)),
        ("utility", utility_plot(load_events(root))),
        ("path", path_plot(trajectory)),
    ]
    sections = _metrics_sections(root)
    title = f"Mission run {root.name}"
    return _write_page(root / REPORT_FILE, title, figures, sections, thumbnails)


def mission_scene_figure(world: World, graph: LayeredSemanticGraph, trajectory: NDArray):
    """The 3DLSG's layers stacked above the world's footprints, with the robot's path."""
    figure = go.Figure()
    figure.add_trace(_footprint_trace(world))
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
        figure.add_trace(_segments_trace(pairs, f"{kind.value} edges", "#555555", style))
    for layer in LAYER_ORDER:
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        xyz = np.array([lifted[n.id] for n in nodes]).reshape(-1, 3)
        figure.add_trace(
            _node_trace(
                xyz, layer.value.capitalize(), _LAYER_COLOURS[layer],
                [_lsg_hover(n) for n in nodes], [getattr(n, "image", None) or "" for n in nodes],
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
    _scene_layout(figure, "3DLSG over the world (click a legend entry to toggle a layer)")
    return figure


def _lsg_hover(node: Node) -> str:
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


def _footprint_trace(world: World):
    xs: list[float | None] = []
    ys: list[float | None] = []
    for info in world.instances.values():
        ring = np.asarray(info.footprint.exterior.coords)
        xs += [*ring[:, 0].tolist(), None]
        ys += [*ring[:, 1].tolist(), None]
    return go.Scatter3d(
        x=xs, y=ys, z=[None if x is None else 0.0 for x in xs], mode="lines", name="world",
        line={"color": "#999999", "width": 2}, hoverinfo="skip",
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
    return sections


# --- terrain runs ------------------------------------------------------------------------------


def write_terrain_report(run_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a terrain graph directory: layers 1-5 of 001 Fig 1, summary tables."""
    root = Path(run_dir)
    scene = load_terrain_graph(root / "graph.json")
    summary_file = root / "summary.json"
    sections = [Section("Graph", key_value_table(scene.summary()))]
    if summary_file.is_file():
        sections.append(Section("Run", key_value_table(json.loads(summary_file.read_text()))))
    figures = [("scene", terrain_scene_figure(scene))]
    title = f"Terrain scene graph {root.name}"
    return _write_page(root / REPORT_FILE, title, figures, sections, {})


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
    figure.add_trace(_segments_trace(place_links, "place edges", "#444444", "solid"))
    figure.add_trace(_segments_trace(hierarchy, "layer edges", "#aaaaaa", "dot"))
    for layer, name in _TERRAIN_LAYERS.items():
        nodes = [n for n, d in graph.nodes(data=True) if d["layer"] == layer]
        xyz = np.array([at(n) for n in nodes]).reshape(-1, 3)
        node_colours = [_terrain_colour(graph.nodes[n], colours) for n in nodes]
        hover = [_terrain_hover(n, graph.nodes[n]) for n in nodes]
        figure.add_trace(_node_trace(xyz, name, node_colours, hover, [""] * len(nodes)))
    _scene_layout(figure, "Terrain scene graph, layers 1-5 (click a legend entry to toggle)")
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


# --- shared pieces -----------------------------------------------------------------------------


def _node_trace(
    xyz: NDArray, name: str, colour: str | list[str], hover: list[str], images: list[str]
):
    return go.Scatter3d(
        x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], mode="markers", name=f"{name} ({len(xyz)})",
        marker={"size": 5, "color": colour, "line": {"width": 0}}, hovertext=hover,
        hoverinfo="text", customdata=images, meta={"layer": name, "nodes": len(xyz)},
    )  # fmt: skip


def _segments_trace(pairs: Sequence[tuple[NDArray, NDArray]], name: str, colour: str, dash: str):
    """Many line segments as one trace, separated by gaps (one legend entry, fast to draw)."""
    coords: list[list[float | None]] = [[], [], []]
    for a, b in pairs:
        for axis in range(3):
            coords[axis] += [float(a[axis]), float(b[axis]), None]
    return go.Scatter3d(
        x=coords[0], y=coords[1], z=coords[2], mode="lines", name=f"{name} ({len(pairs)})",
        line={"color": colour, "width": 2, "dash": dash}, hoverinfo="skip",
    )  # fmt: skip


def _scene_layout(figure, title: str) -> None:
    figure.update_layout(
        title=title, height=760, margin={"l": 0, "r": 0, "t": 40, "b": 0},
        scene={"aspectmode": "data", "xaxis_title": "x [m]", "yaxis_title": "y [m]"},
        legend={"itemsizing": "constant"},
    )  # fmt: skip


def key_value_table(values: Mapping[str, Any]) -> str:
    """An HTML table of a (possibly nested) mapping; nested mappings become sub-tables."""
    rows = []
    for key, value in values.items():
        if isinstance(value, Mapping):
            cell = key_value_table(value)
        elif isinstance(value, float):
            cell = f"{value:.3f}"
        elif isinstance(value, list | tuple):
            cell = html.escape(", ".join(_short(v) for v in value))
        else:
            cell = html.escape(_short(value))
        rows.append(f"<tr><th>{html.escape(str(key))}</th><td>{cell}</td></tr>")
    return "<table>" + "".join(rows) + "</table>"


def _short(value: Any) -> str:
    if value is None:
        return "-"
    return f"{value:.3f}" if isinstance(value, float) else str(value)


def _thumbnails(root: Path, images: Iterable[str]) -> dict[str, str]:
    """Each referenced image as a small JPEG data URI (missing or unreadable ones are left out)."""
    thumbnails = {}
    for relative in sorted(images):
        image = cv2.imread(str(root / relative), cv2.IMREAD_COLOR)
        if image is None:
            continue
        height = max(1, round(image.shape[0] * THUMBNAIL_WIDTH / image.shape[1]))
        small = cv2.resize(image, (THUMBNAIL_WIDTH, height), interpolation=cv2.INTER_AREA)
        ok, encoded = cv2.imencode(".jpg", small, [cv2.IMWRITE_JPEG_QUALITY, THUMBNAIL_QUALITY])
        if ok:
            thumbnails[relative] = (
                "data:image/jpeg;base64," + base64.b64encode(encoded.tobytes()).decode()
            )
    return thumbnails


#: Shows the hovered node's text and thumbnail beside the 3D view.
_HOVER_SCRIPT = """
const thumbnails = JSON.parse(document.getElementById('thumbnails').textContent);
const scene = document.getElementById('figure-scene');
const panel = document.getElementById('hover-panel');
scene.on('plotly_hover', (event) => {
  const point = event.points[0];
  const text = Array.isArray(point.data.hovertext) ? point.data.hovertext[point.pointNumber] : '';
  const image = point.customdata ? thumbnails[point.customdata] : undefined;
  panel.innerHTML = (text || '') + (image ? '<br><img alt="view" src="' + image + '">' : '');
});
"""

_STYLE = """
body { font-family: sans-serif; margin: 1em 2em; color: #222; }
table { border-collapse: collapse; margin: 0.3em 0; }
th, td { border: 1px solid #ccc; padding: 2px 8px; text-align: left; vertical-align: top; }
th { background: #f3f3f3; font-weight: normal; }
#scene-row { display: flex; gap: 1em; }
#scene-row > div:first-child { flex: 1; min-width: 0; }
#hover-panel { width: 200px; font-size: 0.85em; }
"""


def _write_page(
    path: Path,
    title: str,
    figures: Sequence[tuple[str, Any]],
    sections: Sequence[Section],
    thumbnails: Mapping[str, str],
) -> Path:
    """The page: plotly.js once (inline), the scene with its hover panel, tables, other plots."""
    divs = []
    for index, (name, figure) in enumerate(figures):
        divs.append(
            figure.to_html(
                full_html=False, include_plotlyjs=index == 0, div_id=f"figure-{name}",
                config={"displaylogo": False},
            )
        )  # fmt: skip
    scene, others = divs[0], divs[1:]
    tables = "".join(f"<h2>{html.escape(s.title)}</h2>{s.body}" for s in sections)
    # "</" cannot appear inside a script element; base64 and JSON escapes keep it out
    thumbnail_json = json.dumps(dict(thumbnails)).replace("</", "<\\/")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>{_STYLE}</style></head>
<body><h1>{html.escape(title)}</h1>
<div id="scene-row"><div>{scene}</div>
<div id="hover-panel">Hover a node to see its name, label, score and image.</div></div>
{tables}
{"".join(others)}
<script type="application/json" id="thumbnails">{thumbnail_json}</script>
<script>{_HOVER_SCRIPT}</script>
</body></html>
"""
    return atomic_write_text(path, page)
