"""The mission report's playback: a slider over the run's simulated time.

At time ``t`` the playback figure shows the 3DLSG as it stood then (the nodes that had entered
the graph by ``t``, :func:`~seminspect.missions.xflie.lsg_markers.node_times`, and the edges
between them, stacked as in the scene above it), the robot's pose (a marker and a heading
line) and its trajectory so far; beside it, the latest inspection view: the image of the last
Pose node stamped at or before ``t``.

The page stays small because nothing is repeated per step: every trace of the figure is
sorted by time and carries its times once, in ``customdata``, so what stands at ``t`` is a
prefix of each trace and the slider's handler only slices arrays the figure already holds
(``Plotly.restyle``). A plotly frame per step would copy the whole graph into every frame.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import EdgeKind, Layer, PoseNode, RobotNode
from seminspect.missions.xflie.lsg_markers import node_times
from seminspect.report.html_page import Section, scene_layout
from seminspect.report.lsg import LAYER_COLOURS, LAYER_ORDER, layer_heights, lifted_position

#: The slider moves in steps of this many simulated seconds.
STEP_S = 0.1
#: Play runs through a whole mission in about this many seconds of wall time, however long it
#: was, so a long mission is not tedious and a short one not a blink.
PLAY_THROUGH_S = 30.0
#: Coordinates and times in the figure are rounded to this many decimals (mm, ms): finer
#: digits would only make the page bigger.
_DECIMALS = 3
VIEW_CAPTION = "latest inspection view"


@dataclass(frozen=True, eq=False)
class Playback:
    """What the slider shows at each time: when nodes entered the graph, where the robot was,
    and which view images it had taken."""

    end_s: float
    #: Simulated second at which each node but the robot entered the graph.
    node_times: Mapping[str, float]
    #: ``(stamp, image)`` of every Pose node with an image, in stamp order.
    views: tuple[tuple[float, str], ...]
    #: Rows of ``t, x, y, z, yaw`` (the true pose), in time order; possibly none.
    trajectory: NDArray[np.float64]

    def nodes_at(self, t: float) -> set[str]:
        """The nodes that stood in the graph at ``t``."""
        return {node for node, entered in self.node_times.items() if entered <= t}

    def pose_at(self, t: float) -> NDArray[np.float64] | None:
        """``x, y, z, yaw`` of the last trajectory row at or before ``t`` (the first row
        before the run began; None without a trajectory)."""
        if not len(self.trajectory):
            return None
        row = max(int(np.searchsorted(self.trajectory[:, 0], t, side="right")) - 1, 0)
        return self.trajectory[row, 1:5]

    def view_at(self, t: float) -> str | None:
        """The image of the last Pose node stamped at or before ``t`` (None before the first)."""
        seen = [image for stamp, image in self.views if stamp <= t]
        return seen[-1] if seen else None


def mission_playback(
    graph: LayeredSemanticGraph,
    events: Sequence[Mapping[str, Any]],
    trajectory: NDArray[np.float64],
    images: Collection[str],
) -> Playback:
    """The playback of a run from its graph, events and trajectory; ``images`` are the view
    images the page holds (a view whose image is missing is not shown)."""
    stamps = [n.stamp for n in graph.nodes() if isinstance(n, PoseNode)]
    ends = [float(trajectory[-1, 0])] if len(trajectory) else []
    end_s = max([*ends, *(float(e["t"]) for e in events if "t" in e), *stamps], default=0.0)
    views = sorted(
        (n.stamp, n.image)
        for n in graph.nodes()
        if isinstance(n, PoseNode) and n.image is not None and n.image in images
    )
    rows = np.reshape(trajectory, (-1, trajectory.shape[-1]))[:, :5]
    rows = rows[np.argsort(rows[:, 0], kind="stable")]
    return Playback(end_s, node_times(graph, events, end_s), tuple(views), rows)


def playback_section(
    playback: Playback, graph: LayeredSemanticGraph, footprints: go.Scatter3d
) -> Section | None:
    """The slider, its play button, the figure and the view panel (None for a run that never
    moved the clock: nothing to play back)."""
    if playback.end_s <= 0.0:
        return None
    figure = playback_figure(playback, graph, footprints)
    div = figure.to_html(
        full_html=False, include_plotlyjs=False, div_id="figure-playback",
        config={"displaylogo": False},
    )  # fmt: skip
    limit = _slider_limit(playback.end_s)
    data = {
        "views": [[round(stamp, _DECIMALS), image] for stamp, image in playback.views],
        "heading": _heading_length(graph),
        "layers": [layer.value.capitalize() for layer in LAYER_ORDER],
        "caption": VIEW_CAPTION,
        "rate": limit / PLAY_THROUGH_S,  # simulated seconds per second of Play
    }
    # the view panel comes first in the page and is shown on the right (row-reverse): plotly
    # sizes a figure when it is drawn, so a panel parsed after it would end up beneath it
    body = f"""<p>Drag the slider (or press Play) to replay the mission: the 3DLSG as it stood at
that simulated time, the robot's pose and path so far, and the {VIEW_CAPTION} beside it.</p>
<div id="playback-controls"><button id="playback-play" type="button">Play</button>
<input id="playback-time" type="range" min="0" max="{limit}" step="{STEP_S}" value="{limit}"
 style="width: 60%" aria-label="simulated time">
<span id="playback-clock">t = {limit:.1f} s</span></div>
<div style="display: flex; flex-direction: row-reverse; gap: 1em">
<div id="playback-view" style="width: 200px; flex: none; font-size: 0.85em"></div>
<div style="flex: 1; min-width: 0">{div}</div></div>
<script type="application/json" id="playback-data">{_script_json(data)}</script>
<script>{_PLAYBACK_SCRIPT}</script>"""
    return Section("Playback", body)


def playback_figure(
    playback: Playback, graph: LayeredSemanticGraph, footprints: go.Scatter3d
) -> go.Figure:
    """The whole mission's state (as at its end), each trace in time order with its times in
    ``customdata`` and ``meta = {"playback": kind}`` for the page's slider."""
    figure = go.Figure()
    figure.add_trace(footprints)
    trajectory = playback.trajectory
    figure.add_trace(
        go.Scatter3d(
            x=_rounded(trajectory[:, 1]), y=_rounded(trajectory[:, 2]),
            z=_rounded(trajectory[:, 3]), customdata=_rounded(trajectory[:, [0, 4]]),
            mode="lines", name="trajectory so far", line={"color": "#1f77b4", "width": 3},
            hovertemplate="t=%{customdata[0]:.1f} s<extra></extra>",
            meta={"playback": "trajectory"},
        )
    )  # fmt: skip
    heights = layer_heights(graph)
    times = playback.node_times
    lifted = {n.id: lifted_position(n, heights) for n in graph.nodes() if n.id in times}
    for kind, dash in ((EdgeKind.SPATIAL, "solid"), (EdgeKind.SYMBOLIC, "dot")):
        # an edge stands once both its nodes do (the robot's edges are left out: it moves)
        edges = [
            (max(times[e.u], times[e.v]), lifted[e.u], lifted[e.v])
            for e in graph.edges()
            if e.kind is kind and e.u in lifted and e.v in lifted
        ]
        edges.sort(key=lambda edge: edge[0])
        figure.add_trace(_edges_trace(edges, f"{kind.value} edges", dash))
    for layer in LAYER_ORDER:
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        nodes.sort(key=lambda n: times[n.id])
        xyz = np.array([lifted[n.id] for n in nodes]).reshape(-1, 3)
        name = layer.value.capitalize()
        figure.add_trace(
            go.Scatter3d(
                x=_rounded(xyz[:, 0]), y=_rounded(xyz[:, 1]), z=_rounded(xyz[:, 2]),
                customdata=_rounded(np.array([times[n.id] for n in nodes])), mode="markers",
                name=f"{name} ({len(nodes)})", marker={"size": 4, "color": LAYER_COLOURS[layer]},
                hovertemplate=f"{name} node, in the graph since t=%{{customdata:.1f}} s"
                "<extra></extra>",
                meta={"playback": name},
            )
        )  # fmt: skip
    length = _heading_length(graph)
    _add_robot(figure, playback, length)
    scene_layout(figure, "The mission at the slider's time")
    _hold_the_view(figure, length)
    return figure


def _hold_the_view(figure: go.Figure, margin: float) -> None:
    """Axes fixed to the whole mission's extent (``margin`` more, for the heading line), so
    the view does not jump as the slider adds or removes what it autoranges on."""
    ranges = []
    for axis in "xyz":
        values = [v for trace in figure.data for v in (trace[axis] or ()) if v is not None]
        low, high = (min(values), max(values)) if values else (0.0, 1.0)
        ranges.append((low - margin, high + margin))
    spans = [high - low for low, high in ranges]
    figure.update_scenes(
        xaxis_range=ranges[0], yaxis_range=ranges[1], zaxis_range=ranges[2],
        aspectmode="manual",
        aspectratio={a: span / max(spans) for a, span in zip("xyz", spans, strict=True)},
    )  # fmt: skip


def _edges_trace(
    edges: Sequence[tuple[float, NDArray, NDArray]], name: str, dash: str
) -> go.Scatter3d:
    """``(time, a, b)`` segments separated by gaps, as
    :func:`~seminspect.report.html_page.segments_trace` draws them, with each segment's time on
    its three entries so that a prefix of the trace is whole segments."""
    coords: list[list[float | None]] = [[], [], []]
    stamps: list[float] = []
    for t, a, b in edges:
        for axis in range(3):
            coords[axis] += [round(float(a[axis]), _DECIMALS), round(float(b[axis]), _DECIMALS)]
            coords[axis].append(None)
        stamps += [round(t, _DECIMALS)] * 3
    return go.Scatter3d(
        x=coords[0], y=coords[1], z=coords[2], customdata=stamps, mode="lines", name=name,
        line={"color": "#555555", "width": 2, "dash": dash}, hoverinfo="skip",
        meta={"playback": name},
    )  # fmt: skip


def _add_robot(figure: go.Figure, playback: Playback, length: float) -> None:
    """The robot's marker and heading line at the run's end (the slider moves them)."""
    pose = playback.pose_at(playback.end_s)
    x, y, z, yaw = (float(v) for v in pose) if pose is not None else (0.0, 0.0, 0.0, 0.0)
    tip = (x + length * math.cos(yaw), y + length * math.sin(yaw))
    visible = pose is not None
    figure.add_trace(
        go.Scatter3d(
            x=[x], y=[y], z=[z], mode="markers", name="robot", visible=visible,
            marker={"symbol": "diamond", "size": 7, "color": "black"}, hoverinfo="skip",
            meta={"playback": "robot"},
        )
    )  # fmt: skip
    figure.add_trace(
        go.Scatter3d(
            x=[x, tip[0]], y=[y, tip[1]], z=[z, z], mode="lines", name="heading",
            visible=visible, line={"color": "black", "width": 6}, hoverinfo="skip",
            meta={"playback": "heading"},
        )
    )  # fmt: skip


def _heading_length(graph: LayeredSemanticGraph) -> float:
    """Half the spacing of the stacked layers: long enough to read at the scene's scale."""
    heights = layer_heights(graph)
    return round(0.5 * (heights[Layer.POSE] - heights[Layer.FEATURE]), _DECIMALS)


def _slider_limit(end_s: float) -> float:
    """The slider's end: the run's end rounded up to a step, so its last position shows all."""
    limit = round(math.ceil(end_s / STEP_S) * STEP_S, 6)
    return limit if limit >= end_s else round(limit + STEP_S, 6)


def _rounded(values: NDArray) -> list:
    """Plain JSON lists (plotly would encode an array as base64, which the page's script
    would have to decode before slicing it)."""
    return np.round(np.asarray(values, dtype=float), _DECIMALS).tolist()


def _script_json(value: Any) -> str:
    """JSON safe inside a script element ("</" cannot appear there)."""
    return json.dumps(value).replace("</", "<\\/")


#: The slider's handler: slice each timed trace to its prefix at t, move the robot, show the
#: view. Updates wait for the next animation frame, so dragging redraws at most once a frame.
_PLAYBACK_SCRIPT = """
document.addEventListener('DOMContentLoaded', () => {
  const gd = document.getElementById('figure-playback');
  const slider = document.getElementById('playback-time');
  const clock = document.getElementById('playback-clock');
  const button = document.getElementById('playback-play');
  const panel = document.getElementById('playback-view');
  const data = JSON.parse(document.getElementById('playback-data').textContent);
  const thumbnails = JSON.parse(document.getElementById('thumbnails')?.textContent ?? '{}');
  const time = (c) => (Array.isArray(c) ? c[0] : c);
  const upTo = (times, t) => {  // how many entries of a time-sorted array are at or before t
    let lo = 0, hi = times.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (time(times[mid]) <= t) lo = mid + 1; else hi = mid;
    }
    return lo;
  };
  const kinds = gd.data.map((trace) => trace.meta?.playback);
  const full = gd.data.map((t) => ({x: t.x, y: t.y, z: t.z, c: t.customdata, name: t.name}));
  const timed = full.map((_, i) => i).filter((i) => full[i].c !== undefined);
  const path = full[kinds.indexOf('trajectory')];
  const robot = [kinds.indexOf('robot'), kinds.indexOf('heading')];
  const layers = new Set(data.layers);
  const stamps = data.views.map((view) => view[0]);
  const showView = (t) => {
    const index = upTo(stamps, t) - 1;
    const caption = document.createElement('p');
    panel.replaceChildren(caption);
    if (index < 0 || !thumbnails[data.views[index][1]]) {
      caption.textContent = 'No inspection view yet.';
      return;
    }
    const [stamp, image] = data.views[index];
    caption.textContent = 'The ' + data.caption + ' (t = ' + stamp.toFixed(1) + ' s): ' + image;
    const img = document.createElement('img');
    img.alt = image;
    img.src = thumbnails[image];
    panel.append(img);
  };
  const show = (t) => {
    const update = {x: [], y: [], z: [], name: []};
    for (const i of timed) {
      const k = upTo(full[i].c, t);
      for (const axis of ['x', 'y', 'z']) update[axis].push(full[i][axis].slice(0, k));
      update.name.push(layers.has(kinds[i]) ? kinds[i] + ' (' + k + ')' : full[i].name);
    }
    const traces = [...timed];
    if (path.x.length) {
      const row = Math.max(upTo(path.c, t) - 1, 0);
      const [x, y, z, yaw] = [path.x[row], path.y[row], path.z[row], path.c[row][1]];
      update.x.push([x], [x, x + data.heading * Math.cos(yaw)]);
      update.y.push([y], [y, y + data.heading * Math.sin(yaw)]);
      update.z.push([z], [z, z]);
      update.name.push('robot', 'heading');
      traces.push(...robot);
    }
    Plotly.restyle(gd, update, traces);
    clock.textContent = 't = ' + t.toFixed(1) + ' s';
    showView(t);
  };
  let pending = null;
  const schedule = (t) => {
    if (pending === null) {
      requestAnimationFrame(() => { const next = pending; pending = null; show(next); });
    }
    pending = t;
  };
  slider.addEventListener('input', () => schedule(Number(slider.value)));
  let timer = null;
  const stop = () => { clearInterval(timer); timer = null; button.textContent = 'Play'; };
  button.addEventListener('click', () => {
    if (timer !== null) { stop(); return; }
    const end = Number(slider.max);
    // the clock follows the wall clock, however long each redraw takes
    let t = Number(slider.value) >= end ? 0 : Number(slider.value);
    let last = performance.now();
    button.textContent = 'Pause';
    timer = setInterval(() => {
      const now = performance.now();
      t = Math.min(t + ((now - last) / 1000) * data.rate, end);
      last = now;
      slider.value = t;
      schedule(t);
      if (t >= end) stop();
    }, 50);
  });
  showView(Number(slider.value));
});
"""
