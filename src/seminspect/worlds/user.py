"""User worlds: a mesh file plus a small labels file; saving and reloading any world.

A labels file (JSON or YAML) maps faces of the mesh to instance, class and part::

    format: seminspect-world-labels
    version: 1
    name: parking-lot
    scale: 0.01            # mesh units to metres (optional, default 1)
    up: z                  # "y" turns a Y-up mesh (glTF, many OBJ exports) Z-up
    ground: {margin: 10}   # optional: add a ground plane under the mesh, 10 m around it
    start: {position: [0, -6, 0], yaw: 1.57}
    labels:
      - {groups: ["Hybrid body"], instance: car-1, class: car, part: body}
      - {groups: [Wheels_Rear], box: [[-2, 0, -1], [0, 9, 2]], instance: car-1,
         class: car, part: back-left-wheel}
      - {faces: [[0, 500]], class: wall}

Each entry selects faces by mesh ``groups`` (OBJ ``g``/``o`` names, glTF node or mesh names),
by half-open ``faces`` index ranges, or all faces when neither is given; an optional ``box``
(world coordinates, after scale and up) keeps only faces whose centroid lies inside it. Later
entries override earlier ones. Faces no entry selects are ``background``. An entry without
``instance`` labels background geometry (``class: ground`` marks the floor).

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
import trimesh
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import atomic_write_bytes, read_json, read_yaml, write_versioned_json
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.collision import check_grid_sizes
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.world import BACKGROUND, World

LABELS_FORMAT = "seminspect-world-labels"
LABELS_VERSION = 1
MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".stl", ".off")
LABELS_SUFFIXES = (".json", ".yaml", ".yml")
#: Refuse meshes above this size before parsing them.
MAX_MESH_BYTES = 512 << 20
#: How to shrink a world too large for its collision grids.
_SIZE_FIX = (
    "is its scale right? 'scale: {scale:g}' turns mesh units into metres: use a smaller scale "
    "or tighter 'bounds:'"
)


class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True)

    groups: list[str] | None = None
    faces: list[tuple[int, int]] | None = None
    box: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    instance: str | None = None
    class_name: str = Field(BACKGROUND, alias="class")
    part: str = ""

    @field_validator("faces")
    @classmethod
    def _ranges(cls, ranges: list[tuple[int, int]] | None) -> list[tuple[int, int]] | None:
        for start, stop in ranges or []:
            if not 0 <= start <= stop:
                raise ValueError(f"face range [{start}, {stop}] must satisfy 0 <= start <= stop")
        return ranges


class _Start(BaseModel):
    model_config = ConfigDict(extra="forbid")

    position: tuple[float, float, float]
    yaw: float = 0.0


class _Ground(BaseModel):
    model_config = ConfigDict(extra="forbid")

    margin: float = Field(10.0, ge=0, le=1e4)


class _Labels(BaseModel):
    model_config = ConfigDict(extra="forbid")

    format: Literal["seminspect-world-labels"]
    version: Literal[1]
    name: str = "user"
    scale: float = Field(1.0, gt=0)
    up: Literal["z", "y"] = "z"
    ground: _Ground | None = None
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    start: _Start | None = None
    seed: int = Field(0, ge=0)
    labels: list[_Entry] = []
    metadata: dict[str, Any] = {}


# --------------------------------------------------------------------------------- reading
def _read_labels(path: Path) -> _Labels:
    is_yaml = path.suffix.lower() in (".yaml", ".yml")
    document = read_yaml(path) if is_yaml else read_json(path)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a mapping at the top level")
    try:
        return _Labels.model_validate(document)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "document"
        raise FileFormatError(f"{path}: {where}: {first['msg']}") from None


def _obj_mesh(path: Path) -> tuple[NDArray, NDArray, list[str], NDArray]:
    """Vertices, triangles, group names and the group of each triangle of an OBJ file.

    OBJ ``g``/``o`` names are read straight from the text (trimesh renames groups); polygons are
    split into fans of triangles.
    """
    vertices: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    face_group: list[int] = []
    groups = ["default"]
    current = 0
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read ({exc.strerror})") from None
    for number, line in enumerate(lines, start=1):
        fields = line.split()
        if not fields:
            continue
        try:
            if fields[0] == "v":
                vertices.append([float(x) for x in fields[1:4]])
                if len(vertices[-1]) != 3:
                    raise ValueError("a vertex needs three coordinates")
            elif fields[0] in ("g", "o"):
                name = " ".join(fields[1:]) or "default"
                if name not in groups:
                    groups.append(name)
                current = groups.index(name)
            elif fields[0] == "f":
                corners = [_obj_index(token, len(vertices)) for token in fields[1:]]
                if len(corners) < 3:
                    raise ValueError("a face needs at least three vertices")
                for k in range(1, len(corners) - 1):
                    faces.append((corners[0], corners[k], corners[k + 1]))
                    face_group.append(current)
        except ValueError as exc:
            raise FileFormatError(f"{path}:{number}: {exc}") from None
    if not faces:
        raise FileFormatError(f"{path}: no faces found")
    return np.array(vertices), np.array(faces), groups, np.array(face_group)


def _obj_index(token: str, count: int) -> int:
    index = int(token.split("/", 1)[0])
    resolved = index - 1 if index > 0 else count + index
    if not 0 <= resolved < count:
        raise ValueError(f"vertex index {index} refers to none of the {count} vertices so far")
    return resolved


def _trimesh_mesh(path: Path) -> tuple[NDArray, NDArray, list[str], NDArray]:
    """Vertices, triangles and per-triangle group for formats trimesh reads (glTF nodes)."""
    try:
        scene = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # trimesh raises many types for broken files
        raise FileFormatError(f"{path}: cannot read mesh ({type(exc).__name__}: {exc})") from None
    vertices, faces, group_of, groups = [], [], [], []
    offset = 0
    assert isinstance(scene, trimesh.Scene), "force='scene' loads a scene"
    for node in scene.graph.nodes_geometry:
        matrix, geometry_name = scene.graph[node]
        geometry = scene.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        groups.append(str(node))
        vertices.append(trimesh.transform_points(geometry.vertices, matrix))
        faces.append(np.asarray(geometry.faces) + offset)
        group_of.append(np.full(len(geometry.faces), len(groups) - 1))
        offset += len(geometry.vertices)
        if geometry_name != node:
            groups.append(str(geometry_name))  # the mesh's own name selects the same faces
            group_of[-1] = np.stack([group_of[-1], np.full(len(geometry.faces), len(groups) - 1)])
    if not faces:
        raise FileFormatError(f"{path}: no triangles found")
    return _flatten_groups(vertices, faces, groups, group_of)


def _flatten_groups(
    vertices, faces, groups, group_of
) -> tuple[NDArray, NDArray, list[str], NDArray]:
    """Per-face group membership as a (G, F) boolean table (a face may be in two names)."""
    total = sum(len(f) for f in faces)
    member = np.zeros((len(groups), total), dtype=bool)
    start = 0
    for f, ids in zip(faces, group_of, strict=True):
        for row in np.atleast_2d(ids):
            member[row, np.arange(start, start + len(f))] = True
        start += len(f)
    return np.vstack(vertices), np.vstack(faces), groups, member


def _read_mesh(path: Path) -> tuple[NDArray, NDArray, list[str], NDArray]:
    """Vertices, faces, group names and a (G, F) membership table."""
    if not path.is_file():
        raise FileFormatError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise FileFormatError(
            f"{path}: unsupported mesh type {suffix!r}; use {', '.join(MESH_SUFFIXES)}"
        )
    if path.stat().st_size > MAX_MESH_BYTES:
        raise FileFormatError(f"{path}: larger than {MAX_MESH_BYTES >> 20} MB")
    if suffix == ".obj":
        vertices, faces, groups, face_group = _obj_mesh(path)
        member = face_group[None, :] == np.arange(len(groups))[:, None]
    else:
        vertices, faces, groups, member = _trimesh_mesh(path)
    if not np.all(np.isfinite(vertices)):
        raise FileFormatError(f"{path}: vertices contain NaN or infinity")
    return vertices.astype(np.float64), faces.astype(np.int64), groups, member


# --------------------------------------------------------------------------------- labelling
def _select(entry: _Entry, groups: list[str], member: NDArray, centroids: NDArray, where: str):
    count = member.shape[1]
    if entry.groups is None and entry.faces is None:
        chosen = np.ones(count, dtype=bool)
    else:
        chosen = np.zeros(count, dtype=bool)
    for group in entry.groups or []:
        if group not in groups:
            known = ", ".join(repr(g) for g in groups[:12])
            raise FileFormatError(f"{where}: no mesh group {group!r}; the mesh has {known}")
        chosen |= member[groups.index(group)]
    for start, stop in entry.faces or []:
        if stop > count:
            raise FileFormatError(
                f"{where}: face range [{start}, {stop}) exceeds the {count} faces"
            )
        chosen[start:stop] = True
    if entry.box is not None:
        lo, hi = np.asarray(entry.box[0]), np.asarray(entry.box[1])
        chosen &= np.all((centroids >= lo) & (centroids <= hi), axis=1)
    return chosen


def _assign(labels: _Labels, groups, member, centroids, source: Path):
    """Per-face (instance name, class, part) after applying every entry in order."""
    count = member.shape[1]
    instance = np.full(count, "", dtype=object)
    classes = np.full(count, BACKGROUND, dtype=object)
    parts = np.full(count, "", dtype=object)
    for index, entry in enumerate(labels.labels):
        where = f"{source}: labels[{index}]"
        chosen = _select(entry, groups, member, centroids, where)
        if not chosen.any():
            raise FileFormatError(f"{where}: selects no faces")
        instance[chosen] = entry.instance or ""
        classes[chosen] = entry.class_name
        parts[chosen] = entry.part
    return instance, classes, parts


def _transform(labels: _Labels, vertices: NDArray) -> NDArray:
    points = vertices * labels.scale
    if labels.up == "y":
        points = points @ np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    return points


def load_world(mesh_path: str | os.PathLike[str], labels_path: str | os.PathLike[str]) -> World:
    """Load a user's mesh (OBJ, PLY, GLB/glTF, STL, OFF) with its labels file."""
    source = Path(labels_path)
    labels = _read_labels(source)
    raw, faces, groups, member = _read_mesh(Path(mesh_path))
    if faces.min() < 0 or faces.max() >= len(raw):
        raise FileFormatError(f"{mesh_path}: faces refer to missing vertices")
    vertices = _transform(labels, raw)
    centroids = vertices[faces].mean(axis=1)
    builder = WorldBuilder(labels.name, labels.seed)
    try:
        _add_labelled(builder, vertices, faces, _assign(labels, groups, member, centroids, source))
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        if labels.ground is not None:
            margin = np.array([labels.ground.margin, labels.ground.margin, 0.0])
            builder.add_ground(lo[:2] - margin[:2], hi[:2] + margin[:2], float(lo[2]))
            lo, hi = lo - margin, hi + margin
        bounds = np.array(labels.bounds or [lo, hi + np.array([0.0, 0.0, 2.0])])
        check_grid_sizes(bounds, fix=_SIZE_FIX.format(scale=labels.scale))
        start = labels.start or _Start(position=(bounds[0, 0] + 1.0, bounds[0, 1] + 1.0, lo[2]))
        # the ground is the mesh's lowest point unless the file says otherwise (a saved world)
        metadata = {"ground_z": float(lo[2]), **labels.metadata, "source": str(mesh_path)}
        return builder.build(bounds, start.position, start.yaw, metadata)
    except InvalidInputError as exc:
        raise FileFormatError(f"{source}: {exc}") from None


def load_world_path(path: str | os.PathLike[str]) -> World:
    """A user world named by one path: a directory holding a labels file and one mesh (what
    :func:`save_world` writes), a labels file with one mesh beside it, or a mesh with one
    labels file beside it."""
    source = Path(path)
    if not source.exists():
        raise FileFormatError(f"{source}: no such world file or directory")
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


def _add_labelled(builder: WorldBuilder, vertices, faces, labels: tuple[NDArray, ...]) -> None:
    """Add every face in file order; objects are numbered in order of their first face."""
    instance, classes, parts = labels
    ids: dict[str, int] = {"": 0}
    for name in dict.fromkeys(instance.tolist()):
        if not name:
            continue
        found = sorted(set(classes[instance == name].tolist()))
        if len(found) != 1:
            raise InvalidInputError(f"object {name!r} is labelled with classes {found}")
        ids[name] = builder.new_instance(found[0], name)
    numbers = np.array([ids[name] for name in instance.tolist()], dtype=np.int32)
    builder.add_faces(vertices, faces, classes.tolist(), parts.tolist(), numbers)


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
