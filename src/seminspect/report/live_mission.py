"""The live view of an xFLIE mission: its page and the states it draws.

The page has the 3D scene of report.html (the world's footprints, the occupied voxels of the
robot's map, its path, and the 3DLSG's layers stacked above, 000 Figs 2 and 12), the camera's
latest frame with the detections the mission kept, and the mission's status: simulated time,
phase, targets found and inspected, and the target being pursued with its eq (6) utility.
:class:`MissionFeed` turns each :class:`~seminspect.missions.xflie.live.LiveState` into one
JSON message for a :class:`~seminspect.report.live_server.LiveServer`, and the map, which
changes slowly and is most of the bytes, into a ``map`` message of its own every few seconds.
"""

from __future__ import annotations

import base64
import html
import json
import time
from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import EdgeKind, RobotNode
from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.missions.xflie.live import LiveState
from seminspect.report.html_mission import footprint_lines, node_hover
from seminspect.report.html_page import scene_layout
from seminspect.report.live_server import LiveServer
from seminspect.report.lsg import LAYER_COLOURS, LAYER_ORDER, layer_heights, lifted_position
from seminspect.sensors import Detection, Frame
from seminspect.worlds import World

#: The most occupied voxels a state carries (a regular subsample beyond it).
MAX_MAP_POINTS = 6000
#: The most path points a state carries.
MAX_TRAIL_POINTS = 1000
#: Width of the camera picture [px].
IMAGE_WIDTH = 480
#: Wall seconds between two extractions of the map's occupied voxels (a full-grid pass).
MAP_PERIOD_S = 5.0
_JPEG = [cv2.IMWRITE_JPEG_QUALITY, 70]
_BOX_COLOURS = {"instance": (40, 40, 214), "part": (44, 160, 44)}  # BGR

#: The scene's traces in the page's order; the page's script finds them by these names.
TRACES = ("world", "map", "path", "spatial edges", "symbolic edges",
          *(layer.value.capitalize() for layer in LAYER_ORDER), "robot")  # fmt: skip


class MissionFeed:
    """A mission's live states for ``server``, paced by it (a :class:`LiveFeed`)."""

    def __init__(self, server: LiveServer) -> None:
        self.server = server
        self._map_at = -float("inf")
        self._started = time.monotonic()

    def start(self, world: World) -> None:
        self.server.set_scene({"world": footprint_lines(world)})
        self._started = time.monotonic()

    def ready(self) -> bool:
        return self.server.ready()

    def publish(self, state: LiveState) -> None:
        """The state; before it, every MAP_PERIOD_S and at the end, the map (a full-grid pass,
        and most of a message's bytes: it goes as its own ``map`` event)."""
        if time.monotonic() - self._map_at >= MAP_PERIOD_S or state.ended:
            self.server.send(_xyz(occupied_points(state.occupancy)), event="map")
            self._map_at = time.monotonic()
        self.server.send(self.message(state))

    def message(self, state: LiveState) -> dict[str, Any]:
        """One state as the page's JSON, without the map (see :meth:`publish`)."""
        trajectory = state.trajectory
        pose = trajectory[-1, 1:5].tolist() if len(trajectory) else None
        return {
            "t": round(state.sim_time, 2),
            "budget": state.budget_s,
            "wall": round(time.monotonic() - self._started, 2),
            "phase": state.phase,
            "detected": state.detected,
            "inspected": state.inspected,
            "target": _target(state),
            "pose": pose,
            "traces": {"path": _xyz(_trail(trajectory)), **graph_traces(state.graph)},
            "image": _picture(state),
            "image_kind": _picture_kind(state.frame),
            "detections": [_detection(d) for d in state.detections],
            "final": state.ended,
        }


def _picture(state: LiveState) -> str | None:
    return None if state.frame is None else camera_picture(state.frame, state.detections)


def _picture_kind(frame: Frame | None) -> str | None:
    if frame is None:
        return None
    return "grey image" if frame.intensity is not None else "depth, near bright"


def _target(state: LiveState) -> dict[str, Any] | None:
    terms = state.next_target
    if terms is None:
        return None
    return {"id": terms.target_id, "utility": round(terms.utility, 4)}


def _detection(detection: Detection) -> dict[str, Any]:
    return {
        "label": detection.label,
        "level": detection.level,
        "score": round(detection.score, 3),
        "bbox": list(detection.bbox),
    }


def _xyz(points: NDArray[np.float64]) -> dict[str, list[float]]:
    rounded = np.round(np.asarray(points, dtype=float).reshape(-1, 3), 2)
    return {"x": rounded[:, 0].tolist(), "y": rounded[:, 1].tolist(), "z": rounded[:, 2].tolist()}


def _trail(trajectory: NDArray[np.float64]) -> NDArray[np.float64]:
    """The true path, every k-th row to at most MAX_TRAIL_POINTS, ending where the robot is."""
    step = max(1, -(-len(trajectory) // MAX_TRAIL_POINTS))
    rows = trajectory[::-1][::step][::-1]
    return rows[:, 1:4]


def occupied_points(occupancy: VoxelMap) -> NDArray[np.float64]:
    """Centres of the map's occupied voxels, every k-th to at most MAX_MAP_POINTS."""
    cells = np.argwhere(occupancy.states == OCCUPIED)
    step = max(1, -(-len(cells) // MAX_MAP_POINTS))
    return occupancy.index_to_world(cells[::step])


def graph_traces(graph: LayeredSemanticGraph) -> dict[str, dict[str, list]]:
    """The 3DLSG's layers (with hover text) and edges, lifted as report.html draws them."""
    heights = layer_heights(graph)
    lifted = {node.id: lifted_position(node, heights) for node in graph.nodes()}
    traces: dict[str, dict[str, list]] = {}
    for kind in (EdgeKind.SPATIAL, EdgeKind.SYMBOLIC):
        pairs = [(lifted[e.u], lifted[e.v]) for e in graph.edges() if e.kind is kind]
        traces[f"{kind.value} edges"] = _segments(pairs)
    for layer in LAYER_ORDER:
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        trace: dict[str, list] = _xyz(np.array([lifted[n.id] for n in nodes]))
        trace["text"] = [node_hover(n) for n in nodes]
        traces[layer.value.capitalize()] = trace
    return traces


def _segments(pairs: list[tuple[NDArray, NDArray]]) -> dict[str, list]:
    """Segments as one line trace with gaps (``None``) between them."""
    coords: dict[str, list] = {"x": [], "y": [], "z": []}
    for a, b in pairs:
        for axis, name in enumerate("xyz"):
            coords[name] += [round(float(a[axis]), 2), round(float(b[axis]), 2), None]
    return coords


def camera_picture(frame: Frame, detections: Sequence[Detection]) -> str:
    """The frame as a JPEG data URI with its detections boxed: its grey image, or its depth
    (near bright) for a frame rendered without one (frames taken while driving)."""
    if frame.intensity is not None:
        picture = cv2.cvtColor(frame.intensity, cv2.COLOR_GRAY2BGR)
    else:
        picture = _depth_picture(frame.depth, frame.camera.max_range)
    scale = IMAGE_WIDTH / picture.shape[1]
    picture = cv2.resize(picture, (IMAGE_WIDTH, round(picture.shape[0] * scale)))
    for detection in detections:
        _draw_box(picture, detection, scale)
    encoded, jpeg = cv2.imencode(".jpg", picture, _JPEG)
    if not encoded:
        return ""
    return "data:image/jpeg;base64," + base64.b64encode(jpeg.tobytes()).decode()


def _depth_picture(depth: NDArray[np.float32], max_range: float) -> NDArray[Any]:
    near = np.where(np.isfinite(depth), 1.0 - np.minimum(depth, max_range) / max_range, 0.0)
    return cv2.applyColorMap((255 * near).astype(np.uint8), cv2.COLORMAP_BONE)


def _draw_box(picture: NDArray[Any], detection: Detection, scale: float) -> None:
    x0, y0, x1, y1 = (round(v * scale) for v in detection.bbox)
    colour = _BOX_COLOURS.get(detection.level, (0, 200, 255))
    cv2.rectangle(picture, (x0, y0), (x1 - 1, y1 - 1), colour, 2)
    if detection.level != "instance":
        return  # parts crowd one object: the page lists them under the picture
    caption = f"{detection.label} {detection.score:.2f}"
    cv2.putText(picture, caption, (x0 + 2, max(12, y0 - 4)), cv2.FONT_HERSHEY_SIMPLEX, 0.45,
                colour, 1, cv2.LINE_AA)  # fmt: skip


def live_page(title: str) -> str:
    """The page: an empty scene (filled by the stream), the camera picture and the status."""
    figure = go.Figure()
    styles: dict[str, dict[str, Any]] = {
        "world": {"mode": "lines", "line": {"color": "#999999", "width": 2}},
        "map": {"mode": "markers", "marker": {"size": 1.5, "color": "#7f7f7f", "opacity": 0.5}},
        "path": {"mode": "lines", "line": {"color": "#1f77b4", "width": 3}},
        "spatial edges": {"mode": "lines", "line": {"color": "#555555", "width": 2}},
        "symbolic edges": {
            "mode": "lines",
            "line": {"color": "#555555", "width": 1, "dash": "dot"},
        },
        "robot": {"mode": "markers", "marker": {"symbol": "diamond", "size": 7, "color": "black"}},
    }
    for layer in LAYER_ORDER:
        marker = {"size": 5, "color": LAYER_COLOURS[layer], "line": {"width": 0}}
        styles[layer.value.capitalize()] = {"mode": "markers", "marker": marker}
    for name in TRACES:
        figure.add_trace(go.Scatter3d(x=[], y=[], z=[], name=name, meta={"trace": name},
                                      hoverinfo="text" if name[0].isupper() else "skip",
                                      **styles[name]))  # fmt: skip
    scene_layout(figure, "Live: the map, the path and the 3DLSG as they grow")
    plot = figure.to_html(
        full_html=False, include_plotlyjs="/plotly.min.js", div_id="live-scene",
        config={"displaylogo": False},
    )  # fmt: skip
    return _PAGE.format(
        title=html.escape(title), plot=plot, traces=json.dumps(list(TRACES)), script=_SCRIPT
    )


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1em; color: #222; }}
#live-row {{ display: grid; grid-template-columns: minmax(0, 1fr) 490px; gap: 1em; }}
#status {{ font-size: 0.95em; }} #status th {{ text-align: left; padding-right: 1em; }}
#camera {{ width: 480px; background: #eee; min-height: 360px; display: block; }}
#connection {{ color: #a00; }}
</style></head>
<body><h1>{title}</h1>
<p id="connection">connecting...</p>
<div id="live-row"><div>{plot}</div>
<div id="side"><img id="camera" alt="the camera's latest frame">
<p><span id="camera-caption">camera</span>: <span id="detections"></span></p>
<table id="status"></table></div></div>
<script>const TRACES = {traces};</script>
<script>{script}</script>
</body></html>
"""

_SCRIPT = """
const gd = document.getElementById('live-scene');
const index = Object.fromEntries(TRACES.map((name, i) => [name, i]));
const fmt = (v, d) => (v === null || v === undefined) ? '-' : Number(v).toFixed(d);
function status(state) {
  const rows = [
    ['simulated', `${fmt(state.t, 1)} / ${fmt(state.budget, 0)} s`],
    ['real time', state.wall > 0 ? `${fmt(state.t / state.wall, 1)}x` : '-'],
    ['phase', state.phase],
    ['targets found / inspected', `${state.detected} / ${state.inspected}`],
    ['pursuing', state.target ? `${state.target.id} (U = ${fmt(state.target.utility, 3)})` : '-'],
  ];
  if (state.final) rows.push(['mission', state.final]);
  const table = document.getElementById('status');
  table.replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    const th = document.createElement('th'); th.textContent = k;
    const td = document.createElement('td'); td.textContent = v; td.dataset.key = k;
    tr.append(th, td); return tr;
  }));
}
function draw(state) {
  const names = Object.keys(state.traces);
  if (state.pose) {
    const [x, y, z] = state.pose;
    state.traces.robot = {x: [x], y: [y], z: [z]};
    names.push('robot');
  }
  const update = {x: [], y: [], z: [], hovertext: [], name: []};
  for (const name of names) {
    const t = state.traces[name];
    update.x.push(t.x); update.y.push(t.y); update.z.push(t.z);
    update.hovertext.push(t.text ?? []);
    update.name.push(t.text ? `${name} (${t.x.length})` : name);
  }
  Plotly.restyle(gd, update, names.map((n) => index[n]));
  if (state.image) {
    document.getElementById('camera').src = state.image;
    document.getElementById('camera-caption').textContent = `camera (${state.image_kind})`;
  }
  document.getElementById('detections').textContent = state.detections.length
    ? state.detections.map((d) => `${d.label} ${d.score.toFixed(2)}`).join(', ')
    : 'no detections in this frame';
  status(state);
  document.body.dataset.simTime = state.t;
}
const source = new EventSource('/events');
source.onopen = () => { document.getElementById('connection').textContent = ''; };
source.addEventListener('scene', (event) => {
  const scene = JSON.parse(event.data);
  Plotly.restyle(gd, {x: [scene.world.x], y: [scene.world.y],
                      z: [scene.world.x.map((v) => v === null ? null : 0)]}, [index.world]);
});
source.addEventListener('map', (event) => {
  const map = JSON.parse(event.data);
  Plotly.restyle(gd, {x: [map.x], y: [map.y], z: [map.z]}, [index.map]);
});
source.onmessage = (event) => {
  const state = JSON.parse(event.data);
  draw(state);
  if (state.final) {
    source.close();
    document.getElementById('connection').textContent = `mission ${state.final}`;
  }
};
source.onerror = () => {
  if (source.readyState === EventSource.CLOSED) return;
  document.getElementById('connection').textContent = 'connection lost; retrying...';
};
"""
