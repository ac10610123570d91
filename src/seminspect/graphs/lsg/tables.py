"""The layers of a 3DLSG as tables: one row per node, one per edge, written as CSV.

Each row is a flat ``dict`` (no pandas needed; ``pandas.DataFrame(rows)`` takes it as is) whose
keys are the columns below, in this order. Positions are split into ``x, y, z`` (metres),
orientations into ``qx, qy, qz, qw`` (with the heading ``yaw`` in radians), and every node names
its ``parent``: the node whose local graph holds it (000 Sec IV-A).

=========  ==============================================================================
table      columns
=========  ==============================================================================
targets    id, parent, index, label, status, x, y, z, score, mask_area, utility,
           observations, stamp, image, levels, polygon_vertices
levels     id, parent, name, index, x, y, z, stamp, closed, poses
poses      id, parent, target, name, index, x, y, z, qx, qy, qz, qw, yaw, stamp, image, features
features   id, parent, level, target, name, label, x, y, z, score, mask_area, image
edges      u, v, kind, weight, via_points (one table per layer: the edges of its local graphs)
polygons   target, vertex, x, y (the containment polygon of each inspected target)
=========  ==============================================================================

``levels``, ``poses`` and ``features`` count a node's children; ``image`` is the reference the
graph holds (relative to the graph file's folder in a run directory), empty when there is none;
``via_points`` counts the points realising a spatial edge (the JSON file keeps the polyline).
The robot, parent of the Target layer, has the row :data:`ROBOT_COLUMNS`.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Final

from seminspect.core.errors import InvalidInputError
from seminspect.core.io import atomic_write_text
from seminspect.graphs.lsg.model import (
    Edge,
    FeatureNode,
    Layer,
    LevelNode,
    Node,
    PoseNode,
    RobotNode,
    TargetNode,
)
from seminspect.graphs.lsg.structure import GraphStructure

Cell = str | int | float | bool | None
Row = dict[str, Cell]

COLUMNS: Final[dict[Layer, tuple[str, ...]]] = {
    Layer.TARGET: (
        *("id", "parent", "index", "label", "status", "x", "y", "z", "score", "mask_area"),
        *("utility", "observations", "stamp", "image", "levels", "polygon_vertices"),
    ),
    Layer.LEVEL: ("id", "parent", "name", "index", "x", "y", "z", "stamp", "closed", "poses"),
    Layer.POSE: (
        *("id", "parent", "target", "name", "index", "x", "y", "z"),
        *("qx", "qy", "qz", "qw", "yaw", "stamp", "image", "features"),
    ),
    Layer.FEATURE: (
        *("id", "parent", "level", "target", "name", "label", "x", "y", "z"),
        *("score", "mask_area", "image"),
    ),
}
ROBOT_COLUMNS: Final = ("id", "x", "y", "z", "qx", "qy", "qz", "qw", "yaw", "stamp")
EDGE_COLUMNS: Final = ("u", "v", "kind", "weight", "via_points")
POLYGON_COLUMNS: Final = ("target", "vertex", "x", "y")


def _xyz(node: Node) -> Row:
    return dict(zip(("x", "y", "z"), (float(c) for c in node.position), strict=True))


def _orientation(node: RobotNode | PoseNode) -> Row:
    quat = (float(c) for c in node.orientation)
    return {**dict(zip(("qx", "qy", "qz", "qw"), quat, strict=True)), "yaw": node.yaw}


def _parent_id(node: TargetNode | LevelNode | PoseNode | FeatureNode) -> str | None:
    return None if node.parent is None else node.parent.id


def robot_row(robot: RobotNode) -> Row:
    """The robot's row (:data:`ROBOT_COLUMNS`)."""
    return {"id": robot.id, **_xyz(robot), **_orientation(robot), "stamp": robot.stamp}


def target_row(target: TargetNode) -> Row:
    """A target's row (``COLUMNS[Layer.TARGET]``)."""
    polygon = target.polygon
    return {
        "id": target.id,
        "parent": _parent_id(target),
        "index": target.index,
        "label": target.label,
        "status": target.status.value,
        **_xyz(target),
        "score": target.score,
        "mask_area": target.mask_area,
        "utility": target.utility,
        "observations": target.observations,
        "stamp": target.stamp,
        "image": target.image,
        "levels": len(target.levels),
        "polygon_vertices": 0 if polygon is None else len(polygon),
    }


def level_row(level: LevelNode) -> Row:
    """A level's row (``COLUMNS[Layer.LEVEL]``)."""
    return {
        "id": level.id,
        "parent": _parent_id(level),
        "name": level.name,
        "index": level.index,
        **_xyz(level),
        "stamp": level.stamp,
        "closed": level.closed,
        "poses": len(level.poses),
    }


def pose_row(pose: PoseNode) -> Row:
    """A view pose's row (``COLUMNS[Layer.POSE]``)."""
    return {
        "id": pose.id,
        "parent": _parent_id(pose),
        "target": None if pose.parent is None else pose.level.target_id,
        "name": pose.name,
        "index": pose.index,
        **_xyz(pose),
        **_orientation(pose),
        "stamp": pose.stamp,
        "image": pose.image,
        "features": len(pose.features),
    }


def feature_row(feature: FeatureNode) -> Row:
    """A feature's row (``COLUMNS[Layer.FEATURE]``)."""
    placed = feature.parent is not None and feature.parent.parent is not None
    return {
        "id": feature.id,
        "parent": _parent_id(feature),
        "level": feature.level.id if placed else None,
        "target": feature.level.target_id if placed else None,
        "name": feature.name,
        "label": feature.label,
        **_xyz(feature),
        "score": feature.score,
        "mask_area": feature.mask_area,
        "image": feature.image,
    }


def node_row(node: Node) -> Row:
    """The row of any node, by its kind."""
    if isinstance(node, RobotNode):
        return robot_row(node)
    if isinstance(node, TargetNode):
        return target_row(node)
    if isinstance(node, LevelNode):
        return level_row(node)
    if isinstance(node, PoseNode):
        return pose_row(node)
    return feature_row(node)


def edge_row(edge: Edge) -> Row:
    """An edge's row (:data:`EDGE_COLUMNS`)."""
    return {
        "u": edge.u,
        "v": edge.v,
        "kind": edge.kind.value,
        "weight": edge.weight,
        "via_points": 0 if edge.via is None else len(edge.via),
    }


_LAYER_NODES: Final[dict[Layer, Callable[[GraphStructure], Sequence[Node]]]] = {
    Layer.TARGET: GraphStructure.targets,
    Layer.LEVEL: GraphStructure.levels,
    Layer.POSE: GraphStructure.poses,
    Layer.FEATURE: GraphStructure.features,
}


def layer_rows(graph: GraphStructure, layer: Layer) -> list[Row]:
    """One row per node of ``layer`` (the robot is not a row: it is the targets' parent)."""
    return [node_row(node) for node in _LAYER_NODES[layer](graph)]


def layer_edge_rows(graph: GraphStructure, layer: Layer) -> list[Row]:
    """One row per edge of the local graphs of ``layer`` (as many as its population counts)."""
    return [edge_row(e) for local in graph.local_graphs(layer) for e in local.edges.values()]


def polygon_rows(graph: GraphStructure) -> list[Row]:
    """One row per vertex of each inspected target's containment polygon, in order."""
    return [
        {"target": target.id, "vertex": i, "x": float(x), "y": float(y)}
        for target in graph.targets()
        if target.polygon is not None
        for i, (x, y) in enumerate(target.polygon)
    ]


def csv_text(rows: Sequence[Row], columns: Sequence[str]) -> str:
    """Rows as CSV with a header; ``None`` is an empty cell, floats are written exactly."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def export_csv(graph: GraphStructure, directory: str | os.PathLike[str]) -> list[Path]:
    """Write ``targets.csv``, ``levels.csv``, ``poses.csv``, ``features.csv``, an
    ``<layer>_edges.csv`` per layer and ``polygons.csv`` into ``directory`` (created if missing),
    each file atomically; returns the paths written."""
    folder = Path(directory)
    if folder.exists() and not folder.is_dir():
        raise InvalidInputError(f"{folder} is a file; give a folder to write the CSV tables in")
    folder.mkdir(parents=True, exist_ok=True)
    tables: list[tuple[str, list[Row], Sequence[str]]] = []
    for layer in Layer:
        tables.append((f"{layer.value}s.csv", layer_rows(graph, layer), COLUMNS[layer]))
        tables.append((f"{layer.value}_edges.csv", layer_edge_rows(graph, layer), EDGE_COLUMNS))
    tables.append(("polygons.csv", polygon_rows(graph), POLYGON_COLUMNS))
    return [atomic_write_text(folder / name, csv_text(rows, cols)) for name, rows, cols in tables]
