"""Saving, loading and exporting 3DLSGs.

* **JSON** (``seminspect.lsg`` version 1) is the native, lossless format: the nested layers as
  the paper draws them (targets hold levels, levels hold poses, poses hold features), plus the
  Target-layer edges and the parameters. Edges inside a target are implied by the structure
  (level chain, pose chain closed through its level, feature-to-pose links) and rebuilt on load.
  Images are referenced by path, never embedded.
* **GraphML** flattens the unified graph for common graph tools (Gephi, yEd, networkx).
* **spark-dsg** (optional extra ``spark``) writes the layered graph in the scene-graph format of
  Hydra and its tools, one named layer per 3DLSG layer.

Loading validates everything a file claims. A malformed, truncated, hostile or wrong-version
file raises :class:`~seminspect.core.errors.FileFormatError` with one line saying what is wrong.
A file is rebuilt node by node through the graph's public building methods (``add_target``,
``add_level``, ``add_pose``, ``add_feature``, ``close_ring``), the ones the registration
operators use, rather than through the operators themselves, which would rename and prune what
the file holds.
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path
from typing import Annotated, Any, Final, Literal

import networkx as nx
import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StringConstraints, ValidationError

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.core.io import (
    atomic_output,
    atomic_write_with,
    read_versioned_json,
    write_versioned_json,
)
from seminspect.core.params import make_params
from seminspect.graphs.lsg import naming
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import (
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    PoseNode,
    TargetNode,
    TargetStatus,
)
from seminspect.graphs.lsg.networkx_view import node_attributes, to_networkx

FORMAT: Final = "seminspect.lsg"
VERSION: Final = 1
#: Structural limits that keep a hostile file from exhausting memory.
MAX_ITEMS = 1_000_000
#: Largest graph file loaded (~17,000 inspected vehicles of 20 views each); see
#: docs/scene-graph.md for the memory a load takes (measured by bench/graph_io.py).
MAX_GRAPH_BYTES = 256 << 20

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Vec2 = Annotated[list[float], Field(min_length=2, max_length=2)]
Quat = Annotated[list[float], Field(min_length=4, max_length=4)]
Name = Annotated[str, StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_.-]{0,79}$")]
Label = Annotated[str, StringConstraints(pattern=r"^[A-Za-z][A-Za-z0-9_ .-]{0,63}$")]
ImageRef = Annotated[str, StringConstraints(min_length=1, max_length=4096)]
Score = Annotated[float, Field(ge=0.0, le=1.0)]
Area = Annotated[float, Field(ge=0.0)]


class _Record(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


class FeatureRecord(_Record):
    name: Name
    label: Label
    position: Vec3
    score: Score
    mask_area: Area
    image: ImageRef | None = None


class PoseRecord(_Record):
    name: Name
    position: Vec3
    orientation: Quat
    image: ImageRef | None = None
    stamp: float = 0.0
    features: Annotated[list[FeatureRecord], Field(max_length=MAX_ITEMS)] = []


class LevelRecord(_Record):
    name: Name
    position: Vec3
    stamp: float = 0.0
    poses: Annotated[list[PoseRecord], Field(max_length=MAX_ITEMS)] = []
    #: Whether the last pose links back to the level (left out when the robot could not
    #: drive it straight); written only when False.
    ring: bool = True
    #: Realisation of the edge from the previous level, oriented from it to this one.
    via: Annotated[list[Vec3], Field(max_length=MAX_ITEMS)] | None = None


class TargetRecord(_Record):
    name: Name
    index: Annotated[int, Field(ge=0)]
    label: Label
    status: Literal["detected", "inspected"]
    position: Vec3
    score: Score
    mask_area: Area
    image: ImageRef | None = None
    stamp: float = 0.0
    utility: float = 0.0
    observations: Annotated[int, Field(ge=1)] = 1
    polygon: Annotated[list[Vec2], Field(min_length=3, max_length=MAX_ITEMS)] | None = None
    levels: Annotated[list[LevelRecord], Field(max_length=10_000)] = []


class TargetEdgeRecord(_Record):
    a: Name
    b: Name
    via: Annotated[list[Vec3], Field(max_length=MAX_ITEMS)] | None = None


class RobotRecord(_Record):
    position: Vec3
    orientation: Quat
    stamp: float = 0.0


class GraphHeader(_Record):
    """Everything in a graph file but its targets (:func:`load_graph` takes those one by one)."""

    format: Literal["seminspect.lsg"] = FORMAT
    version: Literal[1] = VERSION
    params: dict[str, float | int]
    robot: RobotRecord
    next_target_index: Annotated[int, Field(ge=0)]
    target_edges: Annotated[list[TargetEdgeRecord], Field(max_length=MAX_ITEMS)] = []


class GraphDocument(GraphHeader):
    targets: Annotated[list[TargetRecord], Field(max_length=MAX_ITEMS)]


# ---------------------------------------------------------------------- saving
def graph_document(graph: LayeredSemanticGraph) -> dict[str, Any]:
    """The JSON payload of a graph (what :func:`save_graph` writes, without the envelope)."""
    if graph.inspecting is not None:
        raise InvalidInputError(
            f"{graph.inspecting.id} is being inspected; finish or abort the inspection first"
        )
    spatial = [e for e in graph.target_graph.edges.values() if e.kind is EdgeKind.SPATIAL]
    return {
        "params": graph.params.model_dump(),
        "robot": {
            "position": graph.robot.position.tolist(),
            "orientation": graph.robot.orientation.tolist(),
            "stamp": graph.robot.stamp,
        },
        "next_target_index": graph.next_target_index,
        "targets": [_target_record(graph, t) for t in graph.targets()],
        "target_edges": [
            {"a": e.u, "b": e.v, "via": None if e.via is None else e.via.tolist()} for e in spatial
        ],
    }


def _target_record(graph: LayeredSemanticGraph, target: TargetNode) -> dict[str, Any]:
    levels = target.levels
    return {
        "name": target.id,
        "index": target.index,
        "label": target.label,
        "status": target.status.value,
        "position": target.position.tolist(),
        "score": target.score,
        "mask_area": target.mask_area,
        "image": target.image,
        "stamp": target.stamp,
        "utility": target.utility,
        "observations": target.observations,
        "polygon": None if target.polygon is None else target.polygon.tolist(),
        "levels": [
            _level_record(graph, level, levels[i - 1] if i else None)
            for i, level in enumerate(levels)
        ],
    }


def _level_record(
    graph: LayeredSemanticGraph, level: LevelNode, previous: LevelNode | None
) -> dict[str, Any]:
    record: dict[str, Any] = {
        "name": level.name,
        "position": level.position.tolist(),
        "stamp": level.stamp,
        "poses": [_pose_record(pose) for pose in level.poses],
    }
    poses = level.poses
    if len(poses) > 1 and graph.edge(poses[-1].id, level.id) is None:
        record["ring"] = False
    link = None if previous is None else graph.edge(previous.id, level.id)
    if link is not None and link.via is not None:  # kept along the edge's key, written forward
        forward = previous is not None and link.u == previous.id
        record["via"] = (link.via if forward else link.via[::-1]).tolist()
    return record


def _pose_record(pose: PoseNode) -> dict[str, Any]:
    return {
        "name": pose.name,
        "position": pose.position.tolist(),
        "orientation": pose.orientation.tolist(),
        "image": pose.image,
        "stamp": pose.stamp,
        "features": [
            {
                "name": f.name,
                "label": f.label,
                "position": f.position.tolist(),
                "score": f.score,
                "mask_area": f.mask_area,
                "image": f.image,
            }
            for f in pose.features
        ],
    }


def save_graph(graph: LayeredSemanticGraph, path: str | os.PathLike[str]) -> Path:
    """Write the graph as versioned JSON, atomically."""
    return write_versioned_json(path, FORMAT, VERSION, graph_document(graph))


# ---------------------------------------------------------------------- loading
def example_graph_path() -> Path:
    """The small graph shipped with seminspect (five inspected vehicles; ``example`` in the
    ``seminspect graph`` commands)."""
    return Path(str(files("seminspect") / "data" / "example_graph.json"))


def load_graph(path: str | os.PathLike[str]) -> LayeredSemanticGraph:
    """Read a graph written by :func:`save_graph`; any defect raises :class:`FileFormatError`.

    Files above :data:`MAX_GRAPH_BYTES` are refused before they are read. Targets are validated
    and rebuilt one at a time, each dropping its part of the parsed file, so memory peaks near
    the parsed JSON rather than the JSON plus a validated copy plus the graph.
    """
    raw = read_versioned_json(path, FORMAT, [VERSION], max_bytes=MAX_GRAPH_BYTES)
    targets = raw.pop("targets", None)
    if not isinstance(targets, list) or len(targets) > MAX_ITEMS:
        raise FileFormatError(f"{path}: invalid graph file at targets: expected a list of targets")
    try:
        header = GraphHeader.model_validate(raw)
        graph = _start_graph(header)
        for index in range(len(targets)):
            record, targets[index] = _target_at(targets, index), None
            _restore_target(graph, record)
        return _finish_graph(graph, header)
    except ValidationError as exc:
        raise FileFormatError(f"{path}: {_first_error(exc)}") from None
    except SeminspectError as exc:
        raise FileFormatError(f"{path}: {exc}") from None


def _target_at(targets: list[Any], index: int) -> TargetRecord:
    try:
        return TargetRecord.model_validate(targets[index])
    except ValidationError as exc:
        raise FileFormatError(_first_error(exc, ("targets", index))) from None


def _first_error(exc: ValidationError, within: tuple[str | int, ...] = ()) -> str:
    error = exc.errors()[0]
    where = ".".join(str(part) for part in (*within, *error["loc"])) or "document"
    return f"invalid graph file at {where}: {error['msg']}"


def graph_from_document(document: GraphDocument) -> LayeredSemanticGraph:
    """Rebuild a graph from a validated document (structure checked as it is rebuilt)."""
    graph = _start_graph(document)
    for record in document.targets:
        _restore_target(graph, record)
    return _finish_graph(graph, document)


def _start_graph(header: GraphHeader) -> LayeredSemanticGraph:
    robot = header.robot
    graph = LayeredSemanticGraph(make_params(header.params), robot.position)
    graph.robot.orientation = _unit(robot.orientation, "the robot")
    graph.robot.stamp = robot.stamp
    return graph


def _finish_graph(graph: LayeredSemanticGraph, header: GraphHeader) -> LayeredSemanticGraph:
    """The Target-layer edges and the index counter, once every target is in."""
    for edge in header.target_edges:  # ``via`` is stored oriented from ``a`` to ``b``
        graph.connect_targets(edge.a, edge.b, edge.via)
    indices = [t.index for t in graph.targets()]
    if indices and header.next_target_index <= max(indices):
        raise InvalidInputError("next_target_index must exceed every target index")
    graph.next_target_index = header.next_target_index
    return graph


def _restore_target(graph: LayeredSemanticGraph, record: TargetRecord) -> None:
    _expect(record.name, naming.target_name(record.label, record.index))
    if record.name in graph:
        raise InvalidInputError(f"duplicate target {record.name!r}")
    target = TargetNode(
        id=record.name,
        label=record.label,
        index=record.index,
        position=np.asarray(record.position, dtype=np.float64),
        score=record.score,
        mask_area=record.mask_area,
        image=record.image,
        stamp=record.stamp,
        utility=record.utility,
        status=TargetStatus(record.status),
        observations=record.observations,
        polygon=None if record.polygon is None else np.asarray(record.polygon, dtype=np.float64),
    )
    graph.add_target(target)
    if record.levels and not target.inspected:
        raise InvalidInputError(f"{record.name} has levels but is not inspected")
    if target.inspected and not record.levels:
        raise InvalidInputError(f"{record.name} is inspected but has no levels")
    for index, level_record in enumerate(record.levels):
        _restore_level(graph, target, index, level_record)


def _restore_level(
    graph: LayeredSemanticGraph, target: TargetNode, index: int, record: LevelRecord
) -> None:
    _expect(record.name, naming.level_name(index))
    level = LevelNode(
        id=naming.join(target.id, record.name),
        name=record.name,
        index=index,
        target_id=target.id,
        position=np.asarray(record.position, dtype=np.float64),
        stamp=record.stamp,
        closed=True,
    )
    graph.add_level(level, record.via)
    for pose_index, pose_record in enumerate(record.poses):
        _restore_pose(graph, level, pose_index, pose_record)
    if record.ring:
        graph.close_ring(level)


def _restore_pose(
    graph: LayeredSemanticGraph, level: LevelNode, index: int, record: PoseRecord
) -> None:
    _expect(record.name, naming.pose_name(index))
    pose = PoseNode(
        id=naming.join(level.id, record.name),
        name=record.name,
        index=index,
        level_id=level.id,
        position=np.asarray(record.position, dtype=np.float64),
        orientation=_unit(record.orientation, f"{level.id}/{record.name}"),
        image=record.image,
        stamp=record.stamp,
    )
    graph.add_pose(pose)
    for feature in record.features:
        feature_node = FeatureNode(
            id=naming.join(level.id, feature.name),
            name=feature.name,
            label=feature.label,
            pose_id=pose.id,
            position=np.asarray(feature.position, dtype=np.float64),
            score=feature.score,
            mask_area=feature.mask_area,
            image=feature.image,
        )
        graph.add_feature(feature_node)


def _expect(found: str, expected: str) -> None:
    if found != expected:
        raise InvalidInputError(f"expected {expected!r} here, found {found!r}")


def _unit(quat: list[float], owner: str) -> np.ndarray:
    """Quaternions are stored normalised; keep them bit-exact rather than renormalising."""
    q = np.asarray(quat, dtype=np.float64)
    if abs(float(np.linalg.norm(q)) - 1.0) > 1e-6:
        raise InvalidInputError(f"orientation of {owner} is not a unit quaternion")
    return q


# ---------------------------------------------------------------------- exports
def export_graphml(graph: LayeredSemanticGraph, path: str | os.PathLike[str]) -> Path:
    """The unified graph as GraphML (flat attributes; positions as x, y, z)."""
    unified = to_networkx(graph)
    return atomic_write_with(path, lambda buffer: nx.write_graphml(unified, buffer))


#: spark-dsg layer ids: higher = more abstract, as in Hydra's scene graphs.
SPARK_LAYERS = {Layer.FEATURE: 1, Layer.POSE: 2, Layer.LEVEL: 3, Layer.TARGET: 4}


def export_spark_dsg(graph: LayeredSemanticGraph, path: str | os.PathLike[str]) -> Path:
    """Write the graph in spark-dsg's scene-graph format (needs the ``spark`` extra)."""
    try:
        import spark_dsg  # noqa: PLC0415 - optional extra
    except ImportError:
        raise InvalidInputError(
            "spark-dsg export needs the optional extra: pip install 'seminspect[spark]'"
        ) from None
    names = {layer.value + "s": spark_dsg.LayerKey(key) for layer, key in SPARK_LAYERS.items()}
    dsg = spark_dsg.DynamicSceneGraph(list(names.values()), names)
    symbols: dict[str, Any] = {}
    for number, node in enumerate(graph.nodes()):
        attrs = spark_dsg.SemanticNodeAttributes()
        attrs.position = np.asarray(node.position, dtype=np.float64)
        attrs.name = node.id
        attrs.metadata.set(_spark_metadata(node))
        symbols[node.id] = spark_dsg.NodeSymbol(_SPARK_PREFIX[node.layer], number)
        dsg.add_node(node.layer.value + "s", symbols[node.id], attrs)
    for edge in graph.edges():
        info = spark_dsg.EdgeAttributes()
        info.weight = float(edge.weight)
        info.weighted = edge.kind is EdgeKind.SPATIAL
        info.metadata.set({"kind": edge.kind.value})
        dsg.insert_edge(symbols[edge.u], symbols[edge.v], info)
    with atomic_output(path) as tmp:
        dsg.save(tmp, include_mesh=False)
    return Path(path)


_SPARK_PREFIX = {Layer.TARGET: "t", Layer.LEVEL: "l", Layer.POSE: "p", Layer.FEATURE: "f"}


def _spark_metadata(node: Any) -> dict[str, Any]:
    return {k: v for k, v in node_attributes(node).items() if k not in {"x", "y", "z"}}
