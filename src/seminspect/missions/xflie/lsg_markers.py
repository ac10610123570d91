"""A run's final 3DLSG as ``visualization_msgs/MarkerArray`` messages that grow with the mission.

Each node appears at the simulated time it was added to the graph: a target when the events
log says it was ``detected``, a level and a pose at their own stamps (the view that made them),
a feature when its level completed (the n-th ``level-complete`` event of a target closes its
Level-n); a node the log says nothing of appears at the end. Nodes stand where the final graph
has them: a sphere (a pose: an arrow along its heading) and its name, one marker namespace per
layer; edges are line lists, spatial and symbolic apart.

Every message holds the whole graph so far after a ``DELETEALL`` marker, so a viewer that seeks
shows the right graph without replaying what came before. To keep the recording small, the
nodes added within ``period_s`` of the first of them come in one message, at the last one's time.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from seminspect.geometry.transforms import IDENTITY_QUAT
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import (
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    PoseNode,
    TargetNode,
)
from seminspect.mapping.formats.rosbag_writer import header, pose_message, vector_message

MARKER_ARRAY_TYPE = "visualization_msgs/msg/MarkerArray"
_SPHERE, _ARROW, _LINE_LIST, _TEXT = 2, 0, 5, 9  # visualization_msgs/Marker types
_ADD, _DELETE_ALL = 0, 3


@dataclass(frozen=True)
class _Style:
    size: float  # sphere diameter (m); a pose arrow is twice as long
    colour: tuple[float, float, float]


_STYLES = {
    Layer.TARGET: _Style(0.8, (1.0, 0.55, 0.0)),
    Layer.LEVEL: _Style(0.4, (0.2, 0.45, 1.0)),
    Layer.POSE: _Style(0.25, (0.2, 0.8, 0.3)),
    Layer.FEATURE: _Style(0.2, (0.85, 0.2, 0.85)),
}
_EDGE_COLOURS = {EdgeKind.SPATIAL: (0.9, 0.9, 0.9), EdgeKind.SYMBOLIC: (0.55, 0.55, 0.55)}
_EDGE_WIDTH_M = 0.04
#: The nodes drawn: every one but the robot, which is the recording's ``base_link``.
Drawn = TargetNode | LevelNode | PoseNode | FeatureNode


def node_times(
    graph: LayeredSemanticGraph, events: Sequence[Mapping[str, Any]], end_s: float
) -> dict[str, float]:
    """When each node but the robot entered the graph (simulated seconds; ``end_s`` if unknown)."""
    detected: dict[str, float] = {}
    completed: dict[str, list[float]] = {}
    for event in events:
        if event.get("event") == "detected":
            detected.setdefault(str(event.get("target")), float(event["t"]))
        elif event.get("event") == "level-complete":
            completed.setdefault(str(event.get("target")), []).append(float(event["t"]))
    times = {}
    for node in graph.nodes():
        if isinstance(node, TargetNode):
            times[node.id] = detected.get(node.id, end_s)
        elif isinstance(node, LevelNode | PoseNode):
            times[node.id] = node.stamp
        elif isinstance(node, FeatureNode):
            level = node.level
            ends = completed.get(level.target_id, [])
            times[node.id] = ends[level.index] if level.index < len(ends) else end_s
    return times


def marker_arrays(
    types: Mapping[str, Any],
    graph: LayeredSemanticGraph,
    times: Mapping[str, float],
    period_s: float,
    frame: str = "map",
) -> Iterator[tuple[float, Any]]:
    """``(stamp_s, MarkerArray)``: the graph of the nodes in ``times`` as it grew, in time order."""
    nodes = [n for n in graph.nodes() if isinstance(n, Drawn) and n.id in times]
    for stamp in _publish_times(sorted(set(times.values())), period_s):
        present = {node.id: node for node in nodes if times[node.id] <= stamp}
        draw = _Draw(types, round(stamp * 1e9), frame)
        markers = [draw.clear()]
        for index, node in enumerate(present.values()):
            markers += [draw.shape(index, node), draw.name(index, node)]
        markers += _edge_markers(draw, graph, present)
        yield stamp, types[MARKER_ARRAY_TYPE](markers=markers)


def _publish_times(stamps: Sequence[float], period_s: float) -> list[float]:
    """The last time of each window that opens at a node time and lasts ``period_s``."""
    published: list[float] = []
    start = -np.inf
    for stamp in stamps:
        if stamp < start + period_s:
            published[-1] = stamp
        else:
            start = stamp
            published.append(stamp)
    return published


def _edge_markers(draw: _Draw, graph: LayeredSemanticGraph, present: Mapping[str, Drawn]) -> list:
    """One line list per edge kind, of the edges whose two nodes are present."""
    segments: dict[EdgeKind, list[ArrayLike]] = {kind: [] for kind in EdgeKind}
    for edge in graph.edges():
        if edge.u in present and edge.v in present:
            via = [] if edge.via is None else list(edge.via)
            path = [present[edge.u].position, *via, present[edge.v].position]
            for start, end in itertools.pairwise(path):
                segments[edge.kind] += [start, end]
    return [
        draw.lines(index, kind, points)
        for index, (kind, points) in enumerate(segments.items())
        if points
    ]


class _Draw:
    """Markers of one message: one stamp and frame, every other field at its neutral value."""

    def __init__(self, types: Mapping[str, Any], stamp_ns: int, frame: str) -> None:
        self.types = types
        self.header = header(types, stamp_ns, frame)

    def clear(self) -> Any:
        return self._marker("", 0, _SPHERE, action=_DELETE_ALL)

    def shape(self, index: int, node: Drawn) -> Any:
        style = _STYLES[node.layer]
        if isinstance(node, PoseNode):
            size = (2 * style.size, style.size / 3, style.size / 3)
            return self._marker(
                node.layer.value, index, _ARROW, position=node.position,
                orientation=node.orientation, scale=size, colour=style.colour,
            )  # fmt: skip
        return self._marker(
            node.layer.value, index, _SPHERE, position=node.position, scale=(style.size,) * 3,
            colour=style.colour,
        )  # fmt: skip

    def name(self, index: int, node: Drawn) -> Any:
        style = _STYLES[node.layer]
        return self._marker(
            f"{node.layer.value} names", index, _TEXT,
            position=np.add(node.position, (0.0, 0.0, style.size)),
            scale=(0, 0, style.size), colour=style.colour, text=node.name,
        )  # fmt: skip

    def lines(self, index: int, kind: EdgeKind, points: Sequence[ArrayLike]) -> Any:
        vertices = [vector_message(self.types, "Point", p) for p in points]
        return self._marker(
            f"{kind.value} edges", index, _LINE_LIST, scale=(_EDGE_WIDTH_M, 0, 0),
            colour=_EDGE_COLOURS[kind], points=vertices,
        )  # fmt: skip

    def _marker(
        self,
        ns: str,
        index: int,
        kind: int,
        *,
        position: ArrayLike = (0.0, 0.0, 0.0),
        orientation: ArrayLike = IDENTITY_QUAT,
        scale: ArrayLike = (1.0, 1.0, 1.0),
        colour: tuple[float, float, float] = (1.0, 1.0, 1.0),
        action: int = _ADD,
        text: str = "",
        points: Sequence[Any] = (),
    ) -> Any:
        types = self.types
        return types["visualization_msgs/msg/Marker"](
            header=self.header, ns=ns, id=index, type=kind, action=action,
            pose=pose_message(types, position, orientation),
            scale=vector_message(types, "Vector3", scale),
            color=types["std_msgs/msg/ColorRGBA"](*colour, 1.0),
            lifetime=types["builtin_interfaces/msg/Duration"](sec=0, nanosec=0),
            frame_locked=False, points=list(points), colors=[], texture_resource="",
            texture=types["sensor_msgs/msg/CompressedImage"](
                header=self.header, format="", data=np.empty(0, np.uint8)
            ),
            uv_coordinates=[], text=text, mesh_resource="",
            mesh_file=types["visualization_msgs/msg/MeshFile"](
                filename="", data=np.empty(0, np.uint8)
            ),
            mesh_use_embedded_materials=False,
        )  # fmt: skip
