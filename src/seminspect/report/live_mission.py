"""The live view of an xFLIE mission: its page and the states it draws.

The page (:func:`live_page`, on :func:`~seminspect.report.live_common.stream_page`) has the 3D
scene of report.html (the world's footprints, the occupied voxels of the robot's map, its
path, and the 3DLSG's layers stacked above, 000 Figs 2 and 12), the camera's latest frame with
the detections the mission kept, and the mission's status: simulated time, phase, targets
found and inspected, and the target being pursued with its eq (6) utility.
:class:`MissionFeed` turns each :class:`~seminspect.missions.xflie.live.LiveState` into one
JSON message for a :class:`~seminspect.report.live_server.LiveServer`, and the map, which
changes slowly and is most of the bytes, into a ``traces`` message of its own every few
seconds.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import EdgeKind, RobotNode
from seminspect.missions.xflie.live import LiveState
from seminspect.planning.utility import UtilityTerms
from seminspect.report.html_mission import footprint_lines, node_hover
from seminspect.report.live_common import (
    MAP_PERIOD_S,
    camera_picture,
    occupied_points,
    polylines,
    scatter,
    stream_page,
    trail,
    xyz,
)
from seminspect.report.live_server import LiveServer
from seminspect.report.lsg import LAYER_COLOURS, LAYER_ORDER, layer_heights, lifted_position
from seminspect.sensors import Detection, Frame
from seminspect.worlds import World

#: The most path points a state carries.
MAX_TRAIL_POINTS = 1000
#: The 3DLSG's layers as the page names its traces.
LAYERS = tuple(layer.value.capitalize() for layer in LAYER_ORDER)


class MissionFeed:
    """A mission's live states for ``server``, paced by it (a :class:`LiveFeed`)."""

    def __init__(self, server: LiveServer) -> None:
        self.server = server
        self._map_at = -float("inf")
        self._started = time.monotonic()

    def start(self, world: World) -> None:
        lines = footprint_lines(world)
        ground = [None if x is None else 0.0 for x in lines["x"]]
        self.server.set_scene({"traces": {"world": lines | {"z": ground}}})
        self._started = time.monotonic()

    def ready(self) -> bool:
        return self.server.ready()

    def publish(self, state: LiveState) -> None:
        """The state; before it, every MAP_PERIOD_S and at the end, the map (a full-grid pass,
        and most of a message's bytes: it goes as a ``traces`` event of its own)."""
        if time.monotonic() - self._map_at >= MAP_PERIOD_S or state.ended:
            traces = {"map": xyz(occupied_points(state.occupancy))}
            self.server.send({"traces": traces}, event="traces")
            self._map_at = time.monotonic()
        self.server.send(self.message(state))

    def message(self, state: LiveState) -> dict[str, Any]:
        """One state as the page's JSON, without the map (see :meth:`publish`)."""
        trajectory = state.trajectory
        path = trail(trajectory[:, 1:4], MAX_TRAIL_POINTS)
        return {
            "t": round(state.sim_time, 2),
            "pose": trajectory[-1, 1:5].tolist() if len(trajectory) else None,
            "traces": {"path": xyz(path), **graph_traces(state.graph)},
            "image": _picture(state),
            "caption": _caption(state.frame, state.detections),
            "detections": [_detection(d) for d in state.detections],
            "status": self._status(state),
            "final": None if state.ended is None else f"mission {state.ended}",
        }

    def _status(self, state: LiveState) -> list[tuple[str, str]]:
        wall = time.monotonic() - self._started
        target = state.next_target
        rows = [
            ("simulated", f"{state.sim_time:.1f} / {state.budget_s:.0f} s"),
            ("real time", f"{state.sim_time / wall:.1f}x" if wall > 0 else "-"),
            ("phase", state.phase),
            ("targets found / inspected", f"{state.detected} / {state.inspected}"),
            (
                "pursuing",
                "-" if target is None else f"{target.target_id} (U = {target.utility:.3f})",
            ),
        ]
        if state.ended is not None:
            rows.append(("mission", state.ended))
        return rows


def _picture(state: LiveState) -> str | None:
    return None if state.frame is None else camera_picture(state.frame, state.detections)


def _pursued(target: UtilityTerms | None) -> str:
    return "-" if target is None else f"{target.target_id} (U = {target.utility:.3f})"


def _caption(frame: Frame | None, detections: Sequence[Detection]) -> str:
    """What the picture is, and the detections in it (parts are boxed without a name)."""
    if frame is None:
        return "camera: no frame yet"
    kind = "grey image" if frame.intensity is not None else "depth, near bright"
    found = ", ".join(f"{d.label} {d.score:.2f}" for d in detections)
    return f"camera ({kind}): {found or 'no detections in this frame'}"


def _detection(detection: Detection) -> dict[str, Any]:
    return {
        "label": detection.label,
        "level": detection.level,
        "score": round(detection.score, 3),
        "bbox": list(detection.bbox),
    }


def graph_traces(graph: LayeredSemanticGraph) -> dict[str, dict[str, Any]]:
    """The 3DLSG's layers (with hover text) and edges, lifted as report.html draws them."""
    heights = layer_heights(graph)
    lifted = {node.id: lifted_position(node, heights) for node in graph.nodes()}
    traces: dict[str, dict[str, Any]] = {}
    for kind in (EdgeKind.SPATIAL, EdgeKind.SYMBOLIC):
        pairs = [(lifted[e.u], lifted[e.v]) for e in graph.edges() if e.kind is kind]
        traces[f"{kind.value} edges"] = polylines([np.array(pair) for pair in pairs])
    for layer, name in zip(LAYER_ORDER, LAYERS, strict=True):
        nodes = [n for n in graph.nodes() if n.layer is layer and not isinstance(n, RobotNode)]
        trace: dict[str, Any] = xyz(np.array([lifted[n.id] for n in nodes]))
        trace["text"] = [node_hover(n) for n in nodes]
        trace["name"] = f"{name} ({len(nodes)})"
        traces[name] = trace
    return traces


def live_page(title: str) -> str:
    """The page: an empty scene (filled by the stream), the camera picture and the status."""
    traces = [
        scatter("world", mode="lines", line={"color": "#999999", "width": 2}),
        scatter("map", marker={"size": 1.5, "color": "#7f7f7f", "opacity": 0.5}),
        scatter("path", mode="lines", line={"color": "#1f77b4", "width": 3}),
        scatter("spatial edges", mode="lines", line={"color": "#555555", "width": 2}),
        scatter(
            "symbolic edges", mode="lines", line={"color": "#555555", "width": 1, "dash": "dot"}
        ),
        *(
            scatter(name, hover=True, marker={"size": 5, "color": LAYER_COLOURS[layer]})
            for layer, name in zip(LAYER_ORDER, LAYERS, strict=True)
        ),
        scatter("robot", marker={"symbol": "diamond", "size": 7, "color": "black"}),
    ]
    heading = "Live: the map, the path and the 3DLSG as they grow"
    return stream_page(title, heading, traces, "the camera's latest frame")
