"""What the live views of routine inspection (002) and of a policy episode (004) share: one page
whose scene, picture and status all come from the stream, and the helpers that put arrays into
its JSON.

The page (:func:`stream_page`) knows nothing of either program. It holds a plotly 3D scene of
fixed, named traces; the ``scene`` event and every state carry ``traces``, a mapping of trace
name to any of ``x, y, z`` (points), ``i, j, k`` (a mesh's triangles), ``text`` (hover),
``color`` (one marker colour per point) and ``name`` (the legend's label), which the page puts
into those traces with ``Plotly.restyle``. A state also carries ``t`` (the clock the page
exposes as ``body[data-sim-time]``, beside ``data-states``, the count of states drawn),
``pose`` (the ``robot`` trace's point), ``image`` (a data URI) with its ``caption``,
``status`` (rows of the status table, already worded) and ``final`` (None while the run goes
on; then the line that says how it ended, after which the page stops listening). A
``traces`` event carries ``traces`` alone, for parts that change more slowly than the state
and are sent less often (a map). So the wording stays in Python, where it is tested, and the
page stays small.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np
import plotly.graph_objects as go
from numpy.typing import ArrayLike, NDArray

from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.report.html_page import scene_layout
from seminspect.sensors import Detection, Frame

#: The most path points a state carries (every k-th beyond it, the robot's own point kept).
MAX_TRAIL_POINTS = 2000
#: Width of the page's picture [px].
PICTURE_WIDTH = 480
#: The most occupied voxels a map message carries (a regular subsample beyond it).
MAX_MAP_POINTS = 6000
#: Wall seconds between two extractions of a map's occupied voxels (a full-grid pass).
MAP_PERIOD_S = 5.0
_JPEG = [cv2.IMWRITE_JPEG_QUALITY, 75]
_BOX_COLOURS = {"instance": (40, 40, 214), "part": (44, 160, 44)}  # BGR


def xyz(points: NDArray[np.float64]) -> dict[str, list[float]]:
    """``(n, 3)`` points as the page's ``x, y, z`` lists, to the centimetre."""
    rounded = np.round(np.asarray(points, dtype=float).reshape(-1, 3), 2)
    return {"x": rounded[:, 0].tolist(), "y": rounded[:, 1].tolist(), "z": rounded[:, 2].tolist()}


def trail(points: NDArray[np.float64], most: int = MAX_TRAIL_POINTS) -> NDArray[np.float64]:
    """Every k-th point of a path so that at most ``most`` remain, always ending at its last."""
    step = max(1, -(-len(points) // most))
    return np.asarray(points)[::-1][::step][::-1]


def polylines(lines: Sequence[NDArray[np.float64]]) -> dict[str, list[float | None]]:
    """Several ``(n, 3)`` polylines as one line trace, ``None`` between them (no joining line)."""
    coords: dict[str, list[float | None]] = {"x": [], "y": [], "z": []}
    for line in lines:
        for axis, values in xyz(line).items():
            coords[axis] += [*values, None]
    return coords


def box_edges(low: ArrayLike, high: ArrayLike) -> dict[str, list[float | None]]:
    """The twelve edges of an axis-aligned box as one line trace."""
    (x0, y0, z0), (x1, y1, z1) = np.asarray(low, float), np.asarray(high, float)
    ring = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    floors = [np.array([(x, y, z) for x, y in ring]) for z in (z0, z1)]
    posts = [np.array([(x, y, z0), (x, y, z1)]) for x, y in ring[:4]]
    return polylines([*floors, *posts])


def jpeg_uri(picture: NDArray[Any]) -> str:
    """A BGR or grey picture scaled to the page's width, as a JPEG data URI ("" if it fails)."""
    scale = PICTURE_WIDTH / picture.shape[1]
    size = (PICTURE_WIDTH, max(1, round(picture.shape[0] * scale)))
    resized = cv2.resize(picture, size, interpolation=cv2.INTER_NEAREST)
    encoded, jpeg = cv2.imencode(".jpg", resized, _JPEG)
    if not encoded:
        return ""
    return "data:image/jpeg;base64," + base64.b64encode(jpeg.tobytes()).decode()


def occupied_points(occupancy: VoxelMap) -> NDArray[np.float64]:
    """Centres of the map's occupied voxels, every k-th to at most MAX_MAP_POINTS."""
    cells = np.argwhere(occupancy.states == OCCUPIED)
    step = max(1, -(-len(cells) // MAX_MAP_POINTS))
    return occupancy.index_to_world(cells[::step])


def camera_picture(frame: Frame, detections: Sequence[Detection] = ()) -> str:
    """The frame as a JPEG data URI with its detections boxed: its grey image, or its depth
    (near bright) for a frame rendered without one (frames taken while driving)."""
    if frame.intensity is not None:
        picture = cv2.cvtColor(frame.intensity, cv2.COLOR_GRAY2BGR)
    else:
        picture = _depth_picture(frame.depth, frame.camera.max_range)
    for detection in detections:
        _draw_box(picture, detection)
    return jpeg_uri(picture)


def _depth_picture(depth: NDArray[np.float32], max_range: float) -> NDArray[Any]:
    near = np.where(np.isfinite(depth), 1.0 - np.minimum(depth, max_range) / max_range, 0.0)
    return cv2.applyColorMap((255 * near).astype(np.uint8), cv2.COLORMAP_BONE)


def _draw_box(picture: NDArray[Any], detection: Detection) -> None:
    x0, y0, x1, y1 = detection.bbox
    colour = _BOX_COLOURS.get(detection.level, (0, 200, 255))
    cv2.rectangle(picture, (x0, y0), (x1 - 1, y1 - 1), colour, 2)
    if detection.level != "instance":
        return  # parts crowd one object: the caption lists them under the picture
    caption = f"{detection.label} {detection.score:.2f}"
    cv2.putText(picture, caption, (x0 + 2, max(12, y0 - 4)), cv2.FONT_HERSHEY_SIMPLEX, 0.55,
                colour, 1, cv2.LINE_AA)  # fmt: skip


def stream_page(
    title: str, heading: str, traces: Sequence[go.Scatter3d | go.Mesh3d], picture: str
) -> str:
    """The page: ``traces`` (empty, filled by the stream; a ``robot`` trace takes ``pose``), a
    picture described by ``picture`` and the status table (see the module docstring)."""
    figure = go.Figure()
    for trace in traces:
        trace.meta = {"trace": trace.name}
        figure.add_trace(trace)
    scene_layout(figure, heading)
    plot = figure.to_html(
        full_html=False, include_plotlyjs="/plotly.min.js", div_id="live-scene",
        config={"displaylogo": False},
    )  # fmt: skip
    names = [trace.name for trace in traces]
    return _PAGE.format(
        title=html.escape(title), plot=plot, picture=html.escape(picture, quote=True),
        traces=json.dumps(names), script=_SCRIPT,
    )  # fmt: skip


def scatter(name: str, mode: str = "markers", hover: bool = False, **style: Any) -> go.Scatter3d:
    """An empty 3D scatter trace for :func:`stream_page` (hover text only where asked)."""
    return go.Scatter3d(
        x=[], y=[], z=[], name=name, mode=mode, hoverinfo="text" if hover else "skip", **style
    )


def mesh(name: str, colour: str, opacity: float) -> go.Mesh3d:
    """An empty 3D mesh trace for :func:`stream_page`, shown in the legend."""
    return go.Mesh3d(
        x=[], y=[], z=[], i=[], j=[], k=[], name=name, color=colour, opacity=opacity,
        flatshading=True, showlegend=True, hoverinfo="skip",
    )  # fmt: skip


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1em; color: #222; }}
#live-row {{ display: grid; grid-template-columns: minmax(0, 1fr) 490px; gap: 1em; }}
#status {{ font-size: 0.95em; }} #status th {{ text-align: left; padding-right: 1em; }}
#camera {{ width: 480px; background: #eee; min-height: 270px; display: block; }}
#connection {{ color: #a00; }}
</style></head>
<body><h1>{title}</h1>
<p id="connection">connecting...</p>
<div id="live-row"><div>{plot}</div>
<div id="side"><img id="camera" alt="{picture}">
<p id="camera-caption">{picture}</p>
<table id="status"></table></div></div>
<script>const TRACES = {traces};</script>
<script>{script}</script>
</body></html>
"""

_SCRIPT = """
const gd = document.getElementById('live-scene');
const index = Object.fromEntries(TRACES.map((name, i) => [name, i]));
const ATTRIBUTES = {x: 'x', y: 'y', z: 'z', i: 'i', j: 'j', k: 'k', text: 'hovertext',
                    color: 'marker.color', name: 'name'};
function restyle(traces) {
  const groups = {};
  for (const [name, trace] of Object.entries(traces)) {
    if (!(name in index)) continue;
    const keys = Object.keys(trace).filter((key) => key in ATTRIBUTES).sort();
    (groups[keys.join()] ??= {keys, names: []}).names.push(name);
  }
  for (const {keys, names} of Object.values(groups)) {
    const update = {};
    for (const key of keys) update[ATTRIBUTES[key]] = names.map((name) => traces[name][key]);
    Plotly.restyle(gd, update, names.map((name) => index[name]));
  }
}
function status(rows) {
  document.getElementById('status').replaceChildren(...rows.map(([key, value]) => {
    const tr = document.createElement('tr');
    const th = document.createElement('th'); th.textContent = key;
    const td = document.createElement('td'); td.textContent = value; td.dataset.key = key;
    tr.append(th, td); return tr;
  }));
}
function draw(state) {
  const traces = {...state.traces};
  if (state.pose && 'robot' in index) {
    const [x, y, z] = state.pose;
    traces.robot = {x: [x], y: [y], z: [z]};
  }
  restyle(traces);
  if (state.image) document.getElementById('camera').src = state.image;
  if (state.caption) document.getElementById('camera-caption').textContent = state.caption;
  status(state.status);
  document.body.dataset.simTime = state.t;
  document.body.dataset.states = Number(document.body.dataset.states ?? 0) + 1;
}
const source = new EventSource('/events');
source.onopen = () => { document.getElementById('connection').textContent = ''; };
source.addEventListener('scene', (event) => restyle(JSON.parse(event.data).traces));
source.addEventListener('traces', (event) => restyle(JSON.parse(event.data).traces));
source.onmessage = (event) => {
  const state = JSON.parse(event.data);
  draw(state);
  if (state.final) {
    source.close();
    document.getElementById('connection').textContent = state.final;
  }
};
source.onerror = () => {
  if (source.readyState === EventSource.CLOSED) return;
  document.getElementById('connection').textContent = 'connection lost; retrying...';
};
"""
