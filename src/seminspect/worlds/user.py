"""User worlds: a mesh file plus a small labels file; saving and reloading any world.

A labels file (JSON or YAML) maps faces of the mesh to instance, class and part::

    format: seminspect-world-labels
    version: 1
    name: parking-lot
    scale: 0.01            # mesh units to metres (optional, default 1)
    up: z                  # "y" turns a Y-up mesh (glTF, many OBJ exports) Z-up
    ground: {margin: 10}   # optional: a ground plane under the mesh, 10 m around it (z: height)
    start: {position: [0, -6, 0], yaw: 1.57}
    labels:
      - {groups: [Hybrid], instance: car-1, class: car, part: body}
      - {groups: [Wheels_Rear], box: [[-2, 0, -1], [0, 9, 2]], instance: car-1,
         class: car, part: back-left-wheel}
      - {faces: [[0, 500]], class: wall}

Each entry selects faces by mesh ``groups`` (OBJ ``g``/``o`` names, glTF node or mesh names,
COLLADA geometry or node names), by half-open ``faces`` index ranges, or all faces when neither
is given; an optional ``box`` (world coordinates, after scale and up) keeps only faces whose
centroid lies inside it. Later entries override earlier ones. Faces no entry selects are
``background``. An entry without ``instance`` labels background geometry (``class: ground``
marks the floor). Several meshes, each placed by position and yaw, make a site file
(``worlds.site``).

:func:`save_world` writes ``world.ply`` and ``labels.json`` in this format (face ranges), so any
world, generated or loaded, round-trips through :func:`load_world`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import atomic_write_bytes, read_json, read_yaml, write_versioned_json
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.labelling import (
    SIZE_FIX,
    Entry,
    Ground,
    Start,
    add_labelled,
    assign_labels,
    finish_world,
    validated,
)
from seminspect.worlds.meshes import MESH_SUFFIXES, Y_UP, read_mesh
from seminspect.worlds.sdf import SDF_SUFFIXES, load_sdf
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.site import is_site_file, load_site
from seminspect.worlds.world import World

LABELS_FORMAT = "seminspect-world-labels"
LABELS_VERSION = 1
LABELS_SUFFIXES = (".json", ".yaml", ".yml")
#: OctoMap files: maps, refused as worlds with a pointer to where they are used.
OCTOMAP_SUFFIXES = (".bt", ".ot")


class _Labels(BaseModel):
    model_config = ConfigDict(extra="forbid")

    format: Literal["seminspect-world-labels"]
    version: Literal[1]
    name: str = "user"
    scale: float = Field(1.0, gt=0)
    up: Literal["z", "y"] = "z"
    ground: Ground | None = None
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    start: Start | None = None
    seed: int = Field(0, ge=0)
    labels: list[Entry] = []
    metadata: dict[str, Any] = {}


# --------------------------------------------------------------------------------- reading
def _read_labels(path: Path) -> _Labels:
    is_yaml = path.suffix.lower() in (".yaml", ".yml")
    document = read_yaml(path) if is_yaml else read_json(path)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a mapping at the top level")
    return validated(_Labels, document, path)


def _transform(labels: _Labels, vertices: NDArray) -> NDArray:
    points = vertices * labels.scale
    if labels.up == "y":
        points = points @ Y_UP
    return points


def load_world(mesh_path: str | os.PathLike[str], labels_path: str | os.PathLike[str]) -> World:
    """Load a user's mesh (OBJ, PLY, GLB/glTF, STL, OFF, DAE) with its labels file."""
    source = Path(labels_path)
    labels = _read_labels(source)
    raw, faces, groups, member = read_mesh(Path(mesh_path))
    vertices = _transform(labels, raw)
    centroids = vertices[faces].mean(axis=1)
    builder = WorldBuilder(labels.name, labels.seed)
    try:
        where = f"{source}: labels"
        add_labelled(
            builder, vertices, faces, assign_labels(labels.labels, groups, member, centroids, where)
        )
        return finish_world(
            builder,
            vertices,
            ground=labels.ground,
            bounds=labels.bounds,
            start=labels.start,
            metadata={**labels.metadata, "source": str(mesh_path)},
            fix=SIZE_FIX.format(scale=labels.scale),
        )
    except InvalidInputError as exc:
        raise FileFormatError(f"{source}: {exc}") from None


def load_world_path(path: str | os.PathLike[str]) -> World:
    """A user world named by one path: a site file (``worlds.site``), a Gazebo SDF world or
    model (``worlds.sdf``), a directory holding a labels file and one mesh (what
    :func:`save_world` writes), a labels file with one mesh beside it, or a mesh with one
    labels file beside it."""
    source = Path(path)
    if source.suffix.lower() in OCTOMAP_SUFFIXES:
        raise FileFormatError(
            f"{source}: an OctoMap is a map, not a world; use it as a prior with "
            f"'seminspect routine inspect --prior {source}' or plan on it with 'seminspect plan'"
        )
    if not source.exists():
        raise FileFormatError(f"{source}: no such world file or directory")
    if source.is_file() and source.suffix.lower() in SDF_SUFFIXES:
        return load_sdf(source)
    if is_site_file(source):
        return load_site(source)
    folder = source if source.is_dir() else source.parent
    meshes = [source] if _is_mesh(source) else _beside(folder, _is_mesh, "mesh", source)
    labels = [source] if _is_labels(source) else _beside(folder, _is_labels, "labels file", source)
    return load_world(meshes[0], labels[0])


def _is_mesh(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() in MESH_SUFFIXES


def _is_labels(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() in LABELS_SUFFIXES


def _beside(folder: Path, wanted: Callable[[Path], bool], kind: str, given: Path) -> list[Path]:
    """The one file of ``kind`` in ``folder``, or an error saying what a world path is."""
    found = sorted(p for p in folder.iterdir() if wanted(p))
    if len(found) != 1:
        what = "none" if not found else ", ".join(p.name for p in found)
        raise FileFormatError(
            f"{given}: a user world needs exactly one {kind} in {folder} (found {what}); "
            "see 'seminspect world export' for the layout"
        )
    return found


# --------------------------------------------------------------------------------- writing
def _ranges(mask: NDArray[np.bool_]) -> list[list[int]]:
    """Half-open index ranges of the True runs of ``mask``."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return [[int(a), int(b)] for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _entries(world: World) -> list[dict[str, Any]]:
    keys = np.stack([world.face_instance, world.face_class, world.face_part], axis=1)
    entries = []
    for inst, cls, part in np.unique(keys, axis=0).tolist():
        mask = (world.face_instance == inst) & (world.face_class == cls) & (world.face_part == part)
        entry: dict[str, Any] = {"faces": _ranges(mask), "class": world.class_names[cls]}
        if inst:
            entry["instance"] = world.instances[inst].name
        if part:
            entry["part"] = world.part_names[part]
        entries.append(entry)
    return entries


def _ply_bytes(vertices: NDArray, faces: NDArray) -> bytes:
    """Binary little-endian PLY with double-precision vertices, so a world reloads exactly."""
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment seminspect world\n"
        f"element vertex {len(vertices)}\nproperty double x\nproperty double y\n"
        f"property double z\nelement face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    packed = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    packed["n"] = 3
    packed["v"] = faces
    body = np.asarray(vertices, dtype="<f8").tobytes() + packed.tobytes()
    return header.encode("ascii") + body


def save_world(world: World, directory: str | os.PathLike[str]) -> Path:
    """Write ``world.ply`` and ``labels.json`` into ``directory`` (atomically, mesh first)."""
    target = Path(directory)
    if target.exists() and not target.is_dir():
        raise InvalidInputError(f"{target} exists and is not a directory")
    atomic_write_bytes(target / "world.ply", _ply_bytes(world.mesh.vertices, world.mesh.faces))
    metadata = {k: v for k, v in world.metadata.items() if k != "source"}
    payload = {
        "name": world.name,
        "seed": world.seed,
        "bounds": world.bounds.tolist(),
        "start": {"position": world.start_position.tolist(), "yaw": world.start_yaw},
        "labels": _entries(world),
        "metadata": _jsonable(metadata),
    }
    write_versioned_json(target / "labels.json", LABELS_FORMAT, LABELS_VERSION, payload, indent=1)
    return target


def _jsonable(value: Any) -> Any:
    """Keep what JSON can hold (metadata may carry numpy values)."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value if isinstance(value, str | int | float | bool | type(None)) else str(value)


# --------------------------------------------------------------------------------- composing
def insert_world(
    base: World, item: World, position: tuple[float, float, float], yaw: float = 0.0
) -> World:
    """A copy of ``base`` with ``item`` (all its labelled geometry) placed at a pose.

    ``item``'s objects keep their names unless ``base`` already uses one, in which case they
    are renumbered after ``base``'s objects of the same class. ``base`` keeps its bounds,
    start and metadata.
    """
    builder = WorldBuilder(base.name, base.seed)
    _copy_into(builder, base, np.eye(4))
    _copy_into(builder, item, pose_matrix(position, yaw))
    return builder.build(base.bounds, base.start_position, base.start_yaw, dict(base.metadata))


def _copy_into(builder: WorldBuilder, world: World, matrix: NDArray) -> None:
    vertices = np.asarray(world.mesh.vertices) @ matrix[:3, :3].T + matrix[:3, 3]
    taken = set(builder.instance_names())
    renumber = np.zeros(max(world.instances, default=0) + 1, dtype=np.int32)
    for inst, info in world.instances.items():
        renumber[inst] = builder.new_instance(
            info.class_name, None if info.name in taken else info.name
        )
    builder.add_faces(
        vertices,
        world.mesh.faces,
        [world.class_names[c] for c in world.face_class],
        [world.part_names[p] for p in world.face_part],
        renumber[world.face_instance],
    )
