"""Reading triangle meshes with their group names: the mesh half of a user world or site.

OBJ ``g``/``o`` names are read straight from the text (trimesh renames OBJ groups); the other
formats go through trimesh, whose scene nodes and mesh names become the groups. COLLADA (.dae)
needs pycollada, the optional extra ``collada``.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import trimesh
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".stl", ".off", ".dae")
#: Turns a Y-up mesh (glTF, many OBJ and COLLADA exports) Z-up: (x, y, z) -> (x, -z, y).
Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
#: Refuse meshes above this size before parsing them.
MAX_MESH_BYTES = 512 << 20
COLLADA_HINT = "install the extra with pip install 'seminspect[collada]'"


class MeshData(NamedTuple):
    """A mesh as read: vertices, triangles, group names and a (G, F) membership table (a
    face may belong to two names, a glTF node and its mesh)."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    groups: list[str]
    member: NDArray[np.bool_]


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
    vertices: list[NDArray], faces: list[NDArray], groups: list[str], group_of: list[NDArray]
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


def _collada_mesh(path: Path) -> tuple[NDArray, NDArray, list[str], NDArray]:
    """Triangles of every geometry a COLLADA scene instantiates, in metres (the file's
    ``<unit>``) and Z-up (a ``Y_UP`` file is turned), as Gazebo reads them. Each geometry's
    name and id, and the name of the node holding it, select its faces."""
    import collada  # noqa: PLC0415 - the optional extra, checked by read_mesh

    ignored = [collada.common.DaeUnsupportedError, collada.common.DaeBrokenRefError]
    pieces: list[tuple[list[str], NDArray, NDArray]] = []
    with warnings.catch_warnings():
        # pycollada builds numpy.matrix objects, which numpy warns about on every use
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        try:
            document = collada.Collada(str(path), ignore=ignored)
        except Exception as exc:  # pycollada raises many types for broken files
            kind = type(exc).__name__
            raise FileFormatError(f"{path}: cannot read COLLADA ({kind}: {exc})") from None
        if document.scene is None:
            raise FileFormatError(f"{path}: the COLLADA file instantiates no scene")
        for node in document.scene.nodes:
            _collada_node(node, np.asarray(node.matrix), pieces)
    if not pieces:
        raise FileFormatError(f"{path}: no triangles found")
    groups = list(dict.fromkeys(name for names, _, _ in pieces for name in names))
    faces = np.vstack([t + o for (_, _, t), o in zip(pieces, _offsets(pieces), strict=True)])
    member = np.zeros((len(groups), len(faces)), dtype=bool)
    start = 0
    for names, _, triangles in pieces:
        member[[groups.index(n) for n in names], start : start + len(triangles)] = True
        start += len(triangles)
    points = np.vstack([p for _, p, _ in pieces]) * float(document.assetInfo.unitmeter or 1.0)
    if document.assetInfo.upaxis == "Y_UP":
        points = points @ Y_UP
    return points, faces, groups, member


def _offsets(pieces: list[tuple[list[str], NDArray, NDArray]]) -> list[int]:
    counts = [len(points) for _, points, _ in pieces]
    return np.cumsum([0, *counts[:-1]]).tolist()


def _collada_node(node: Any, matrix: NDArray, pieces: list) -> None:
    """Collect (names, vertices, triangles) under one node, its transform applied."""
    import collada  # noqa: PLC0415 - the optional extra

    for child in node.children:
        if isinstance(child, collada.scene.GeometryNode):
            geometry = child.geometry
            names = [n for n in (geometry.name, geometry.id, node.name, node.id) if n]
            for bound in geometry.bind(matrix, {}).primitives():
                triangles = (
                    bound.triangleset()
                    if isinstance(bound, collada.polylist.BoundPolylist)
                    else bound
                )
                if isinstance(triangles, collada.triangleset.BoundTriangleSet):
                    index = np.asarray(triangles.vertex_index).reshape(-1, 3)
                    if len(index):
                        pieces.append((list(dict.fromkeys(names)), triangles.vertex, index))
        elif isinstance(child, collada.scene.Node):
            _collada_node(child, matrix @ np.asarray(child.matrix), pieces)


def read_mesh(path: Path) -> MeshData:
    """Read one mesh file, refusing what it cannot read in one line naming the file."""
    if not path.is_file():
        raise FileFormatError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise FileFormatError(
            f"{path}: unsupported mesh type {suffix!r}; use {', '.join(MESH_SUFFIXES)}"
        )
    if path.stat().st_size > MAX_MESH_BYTES:
        raise FileFormatError(f"{path}: larger than {MAX_MESH_BYTES >> 20} MB")
    if suffix == ".dae" and importlib.util.find_spec("collada") is None:
        raise FileFormatError(f"{path}: reading COLLADA needs pycollada; {COLLADA_HINT}")
    if suffix == ".obj":
        vertices, faces, groups, face_group = _obj_mesh(path)
        member = face_group[None, :] == np.arange(len(groups))[:, None]
    elif suffix == ".dae":
        vertices, faces, groups, member = _collada_mesh(path)
    else:
        vertices, faces, groups, member = _trimesh_mesh(path)
    if not np.all(np.isfinite(vertices)):
        raise FileFormatError(f"{path}: vertices contain NaN or infinity")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise FileFormatError(f"{path}: faces refer to missing vertices")
    return MeshData(vertices.astype(np.float64), faces.astype(np.int64), groups, member)
