"""Saving and loading terrain scene graphs: versioned JSON, GraphML, layer-1 points as NPZ.

The JSON document (``format: seminspect-terrain-graph``) holds layers 2-5, the task and every
parameter. Layer 1 can be large (every task-relevant point) and goes to an ``.npz`` beside it,
named in the document. Readers validate everything: a malformed or hostile file raises
:class:`FileFormatError` with one line.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

import networkx as nx
import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import atomic_write_with, read_versioned_json, save_npz_atomic
from seminspect.core.io import write_versioned_json as _write_json
from seminspect.graphs.terrain.params import TerrainGraphParams
from seminspect.graphs.terrain.prompting import TaskPoints, TaskPrompts
from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph
from seminspect.mapping.semantic_cloud import read_npz
from seminspect.perception.encoders import Calibration

GRAPH_FORMAT = "seminspect-terrain-graph"
GRAPH_VERSION = 1
_VECTORS = ("position", "bbox_min", "bbox_max")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Node(_Strict):
    id: str = Field(min_length=1, max_length=200)
    layer: int = Field(ge=2, le=5)
    kind: Literal["object", "place", "region", "map"]
    position: list[float] = Field(min_length=3, max_length=3)
    label: str | None = None
    terrain: str | None = None
    bbox_min: list[float] | None = Field(None, min_length=3, max_length=3)
    bbox_max: list[float] | None = Field(None, min_length=3, max_length=3)
    points: int | None = Field(None, ge=0)
    score: float | None = None
    cell: list[int] | None = Field(None, min_length=2, max_length=2)
    clearance: float | None = Field(None, ge=0)
    area: float | None = Field(None, ge=0)
    task_mix: list[float] | None = None
    members: int | None = Field(None, ge=0)

    @field_validator("position", "bbox_min", "bbox_max", "task_mix")
    @classmethod
    def _finite(cls, value: list[float] | None) -> list[float] | None:
        if value is not None and not all(math.isfinite(v) for v in value):
            raise ValueError("must be finite numbers")
        return value


class _Edge(_Strict):
    source: str
    target: str
    kind: Literal["gvd", "traversable", "object-place", "region-member", "map-region"]
    length: float | None = Field(None, ge=0)


class _Task(_Strict):
    terrain: list[str]
    objects: list[str]


class _Document(_Strict):
    format: str
    version: int
    encoder: str
    prompts: _Task
    calibration: dict[str, float]
    params: dict[str, float | int]
    layer1_points: dict[str, int]
    layer1_file: str | None = None
    nodes: list[_Node]
    edges: list[_Edge]


def _node_record(node: str, data: dict[str, Any]) -> dict[str, Any]:
    record = {"id": node}
    for key, value in data.items():
        record[key] = np.asarray(value).tolist() if isinstance(value, np.ndarray) else value
    return record


def save_terrain_graph(
    path: str | Path, scene: TerrainSceneGraph, layer1_file: str | None = None
) -> Path:
    """Write layers 2-5 as versioned JSON; with ``layer1_file``, layer 1 goes beside it."""
    target = Path(path)
    if layer1_file is not None:
        if scene.layer1 is None:
            raise InvalidInputError("this graph carries no layer-1 points to save")
        save_layer1(target.parent / layer1_file, scene.layer1)
    payload = {
        "encoder": scene.encoder,
        "prompts": {"terrain": list(scene.prompts.terrain), "objects": list(scene.prompts.objects)},
        "calibration": {
            "terrain": scene.calibration.terrain,
            "objects": scene.calibration.objects,
            "null_task": scene.calibration.null_task,
        },
        "params": scene.params.model_dump(),
        "layer1_points": scene.layer1_counts,
        "layer1_file": layer1_file,
        "nodes": [_node_record(n, d) for n, d in scene.graph.nodes(data=True)],
        "edges": [{"source": a, "target": b, **d} for a, b, d in scene.graph.edges(data=True)],
    }
    return _write_json(target, GRAPH_FORMAT, GRAPH_VERSION, payload)


def _graph_from(document: _Document, source: Path) -> nx.Graph:
    graph = nx.Graph()
    for node in document.nodes:
        if node.id in graph:
            raise FileFormatError(f"{source}: node {node.id!r} appears twice")
        data = node.model_dump(exclude={"id"}, exclude_none=True)
        for key in (*_VECTORS, "task_mix"):
            if key in data:
                data[key] = np.asarray(data[key], dtype=np.float64)
        graph.add_node(node.id, **data)
    for edge in document.edges:
        if edge.source not in graph or edge.target not in graph:
            raise FileFormatError(f"{source}: edge {edge.source!r}-{edge.target!r} has no node")
        graph.add_edge(edge.source, edge.target, **edge.model_dump(exclude={"source", "target"}))
    return graph


def load_terrain_graph(path: str | Path) -> TerrainSceneGraph:
    """Read a graph written by :func:`save_terrain_graph` (and its layer-1 file, if named)."""
    source = Path(path)
    raw = read_versioned_json(source, GRAPH_FORMAT, [GRAPH_VERSION])
    try:
        document = _Document.model_validate(raw)
        prompts = TaskPrompts(tuple(document.prompts.terrain), tuple(document.prompts.objects))
        calibration = Calibration(**document.calibration)
        params = TerrainGraphParams(**document.params)
    except (ValidationError, InvalidInputError, TypeError) as exc:
        raise FileFormatError(f"{source}: invalid terrain graph: {_first_error(exc)}") from None
    graph = _graph_from(document, source)
    layer1 = None
    if document.layer1_file:
        name = Path(document.layer1_file)
        if name.name != document.layer1_file:
            raise FileFormatError(f"{source}: layer1_file must be a plain file name")
        layer1 = load_layer1(source.parent / name, prompts)
    scene = TerrainSceneGraph(
        graph, prompts, document.encoder, calibration, params, document.layer1_points, layer1
    )
    _check_layers(scene, source)
    return scene


def _check_layers(scene: TerrainSceneGraph, source: Path) -> None:
    known_terrain = set(scene.prompts.terrain)
    for node, data in scene.graph.nodes(data=True):
        if data["kind"] == "place" and data.get("terrain") not in known_terrain:
            raise FileFormatError(f"{source}: place {node!r} has an unknown terrain")


def _first_error(exc: Exception) -> str:
    if isinstance(exc, ValidationError):
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"])
        return f"{where}: {first['msg']}"
    return str(exc)


def save_layer1(path: str | Path, layer: TaskPoints) -> Path:
    return save_npz_atomic(
        path,
        points=layer.points,
        classes=layer.classes,
        similarity=layer.similarity,
        source=layer.source,
        prompts=np.array(layer.prompts.all),
    )


def load_layer1(path: str | Path, prompts: TaskPrompts) -> TaskPoints:
    arrays = read_npz(path)
    keys = ("points", "classes", "similarity", "source", "prompts")
    if any(key not in arrays for key in keys):
        raise FileFormatError(f"{path}: layer-1 file lacks one of {', '.join(keys)}")
    if tuple(str(p) for p in arrays["prompts"]) != prompts.all:
        raise FileFormatError(f"{path}: layer-1 prompts differ from the graph's")
    points, classes = arrays["points"], arrays["classes"]
    n = points.shape[0] if points.ndim == 2 else -1
    if (
        points.shape != (n, 3)
        or classes.shape != (n,)
        or arrays["similarity"].shape != (n, len(prompts.all))
        or arrays["source"].shape != (n,)
        or not np.all(np.isfinite(points))
        or (n and (classes.min() < 0 or classes.max() >= len(prompts.all)))
    ):
        raise FileFormatError(f"{path}: layer-1 arrays have inconsistent shapes or values")
    return TaskPoints(prompts, points, classes, arrays["similarity"], arrays["source"])


def write_graphml(path: str | Path, scene: TerrainSceneGraph) -> Path:
    """GraphML for other tools: vectors become ``_x``/``_y``/``_z`` scalar attributes."""
    flat = nx.Graph()
    for node, data in scene.graph.nodes(data=True):
        attributes: dict[str, Any] = {}
        for key, value in data.items():
            if key in _VECTORS:
                attributes.update(
                    {f"{key}_{axis}": float(v) for axis, v in zip("xyz", value, strict=True)}
                )
            elif key == "cell":
                attributes.update({"cell_row": int(value[0]), "cell_col": int(value[1])})
            elif key == "task_mix":
                attributes[key] = " ".join(f"{v:.6g}" for v in value)
            else:
                attributes[key] = value.item() if isinstance(value, np.generic) else value
        flat.add_node(node, **attributes)
    for a, b, data in scene.graph.edges(data=True):
        flat.add_edge(a, b, **{k: v for k, v in data.items() if v is not None})
    return atomic_write_with(path, lambda buffer: nx.write_graphml(flat, buffer))
