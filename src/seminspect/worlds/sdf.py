"""Gazebo SDF worlds and models as seminspect worlds.

The subset read: ``<world>`` with its ``<include>`` (``<uri>``, ``<name>``, ``<pose>``) and
``<model>`` elements; each ``<model>`` with its ``<pose>``, nested models and includes, and its
``<link>/<visual>`` geometry: ``<mesh>`` (``<uri>``, ``<scale>``, ``<submesh>`` with
``<name>`` and ``<center>``), ``<box>``, ``<cylinder>`` and ``<sphere>``. Poses compose model,
link and visual. ``model://NAME/...`` is looked up in each folder of ``$GAZEBO_MODEL_PATH``
(colon-separated), then beside the SDF file and in its parent folder. OBJ and DAE meshes (DAE
through pycollada: ``pip install 'seminspect[collada]'``), and the other mesh types of
``worlds.meshes``. Everything else (lights, physics, plugins, collisions, joints, ...) is
named in one :class:`SiteWarning` per file, never dropped silently.

A class map says which models are targets::

    prius_hybrid: {class: car, forward: -y, parts: {Hybrid: body, Hybrid_Windows: windows}}

keyed by the included name or the model's name; ``parts`` maps mesh groups (OBJ groups, DAE
nodes, a primitive's visual name) to part names; ``forward`` is the axis of the model frame
its front faces. Models not in the map are background obstacles (warned).
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
import trimesh
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_yaml
from seminspect.worlds.checks import WorldWarning
from seminspect.worlds.labelling import Entry, Ground, assign_labels, validated
from seminspect.worlds.meshes import MeshData, read_mesh
from seminspect.worlds.pieces import Layout, Placed, assemble, transform
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.world import BACKGROUND, World

SDF_SUFFIXES = (".sdf", ".world")
MAX_INCLUDE_DEPTH = 8
_FORWARD = {"x": 0.0, "y": math.pi / 2, "-x": math.pi, "-y": -math.pi / 2}
#: Elements read for what they say (everything else is warned about).
_READ = {
    "sdf": {"world", "model"},
    "world": {"include", "model"},
    "include": {"uri", "name", "pose", "static"},
    "model": {"pose", "link", "model", "include", "static"},
    "link": {"pose", "visual"},
    "visual": {"pose", "geometry"},
    "geometry": {"mesh", "box", "cylinder", "sphere"},
    "mesh": {"uri", "scale", "submesh"},
    "submesh": {"name", "center"},
}


class SiteWarning(WorldWarning):
    """Part of a site or SDF file that seminspect does not use (named in the message)."""


class ModelClass(BaseModel):
    """What one SDF model is: its class, its parts by mesh group, the axis it faces."""

    model_config = ConfigDict(extra="forbid", populate_by_name=True)

    class_name: str = Field(alias="class")
    parts: dict[str, str] = {}
    forward: Literal["x", "-x", "y", "-y"] = "x"


ClassMap = dict[str, ModelClass]


class _ClassMapFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    classes: ClassMap


def forward_angle(forward: str) -> float:
    """The direction of a model's front axis, counter-clockwise from +x."""
    return _FORWARD[forward]


class MeshCache:
    """Each mesh file read once, however many visuals or site entries use it."""

    def __init__(self) -> None:
        self._meshes: dict[Path, MeshData] = {}

    def read(self, path: Path) -> MeshData:
        key = path.resolve()
        if key not in self._meshes:
            self._meshes[key] = read_mesh(path)
        return self._meshes[key]


@dataclass
class _Object:
    """One model being read: its instance name, its class-map entry and its pieces."""

    name: str
    kind: ModelClass | None
    pieces: list[Placed] = field(default_factory=list)
    groups_seen: set[str] = field(default_factory=set)


def load_sdf(path: str | os.PathLike[str]) -> World:
    """A world from an SDF world or model file, with the class map ``NAME.classes.yaml``
    beside ``NAME.sdf`` when there is one, and a ground plane at z = 0, 5 m around everything
    (a site file with ``sdf:`` sets ground, bounds and start itself)."""
    source = Path(path)
    beside = source.with_suffix(".classes.yaml")
    classes = read_class_map(beside) if beside.is_file() else {}
    if not classes:
        warnings.warn(
            f"{source}: no class map ({beside.name}): every model is background, so the "
            "world has no targets",
            SiteWarning,
            stacklevel=2,
        )
    pieces = load_sdf_pieces(source, classes, MeshCache())
    layout = Layout(name=_world_name(source), ground=Ground(margin=5.0, z=0.0))
    return assemble(pieces, layout, {}, str(source))


def read_class_map(path: Path) -> ClassMap:
    """A class map file: ``classes:`` mapping model names to class, parts and forward."""
    document = read_yaml(path)
    if not isinstance(document, dict) or not isinstance(document.get("classes"), dict):
        raise FileFormatError(f"{path}: expected 'classes:' mapping model names to classes")
    return validated(_ClassMapFile, document, path).classes


def _world_name(path: Path) -> str:
    root = _parse(path)
    named = root.find("world")
    if named is None:
        named = root.find("model")
    return path.stem if named is None else named.get("name", path.stem)


def load_sdf_pieces(path: Path, classes: ClassMap, cache: MeshCache) -> list[Placed]:
    """The labelled pieces of every visual in an SDF world or model file."""
    reader = _Reader(path, classes, cache)
    reader.read_file(path, np.eye(4), None, 0, None)
    reader.warn()
    return reader.pieces


class _Reader:
    def __init__(self, path: Path, classes: ClassMap, cache: MeshCache) -> None:
        self.path = path
        self.classes = classes
        self.cache = cache
        self.pieces: list[Placed] = []
        self.unread: Counter[str] = Counter()
        self.names: set[str] = set()
        self.notes: list[str] = []
        paths = os.environ.get("GAZEBO_MODEL_PATH", "").split(":")
        self.search = [Path(p) for p in paths if p] + [path.parent, path.parent.parent]

    # ------------------------------------------------------------------ files and models
    def read_file(
        self, path: Path, parent: NDArray, name: str | None, depth: int, placed: NDArray | None
    ) -> None:
        """Read the models of one file: at ``placed`` when an include gives a pose (which
        replaces the model's own), else at their own pose within ``parent``."""
        root = _parse(path)
        self._note_unread(root)
        for child in root:
            if child.tag == "world":
                self._world(child, path)
            elif child.tag == "model":
                at = parent if placed is None else placed
                self._model(child, path, at, name, depth, keep_pose=placed is None)

    def _world(self, world: ET.Element, path: Path) -> None:
        self._note_unread(world)
        for child in world:
            if child.tag == "include":
                self._include(child, path, np.eye(4), 0, None)
            elif child.tag == "model":
                self._model(child, path, np.eye(4), None, 0, keep_pose=True)

    def _include(
        self, element: ET.Element, path: Path, parent: NDArray, depth: int, outer: str | None
    ) -> None:
        self._note_unread(element)
        uri = (element.findtext("uri") or "").strip()
        name = (element.findtext("name") or "").strip() or None
        if depth >= MAX_INCLUDE_DEPTH:
            raise FileFormatError(f"{path}: includes nest deeper than {MAX_INCLUDE_DEPTH}")
        model_file = self._model_file(uri, path)
        wanted = {name, uri.removeprefix("model://").split("/")[0]}
        if model_file is None:
            where = f"{path}: include {uri!r}"
            if wanted & set(self.classes):
                raise FileFormatError(f"{where}: model not found on GAZEBO_MODEL_PATH or beside")
            self.notes.append(f"include {uri!r} (model not found; skipped)")
            return
        pose = element.find("pose")
        placed = None if pose is None else parent @ _pose(pose)
        inner = f"{outer}::{name}" if outer and name else name
        self.read_file(model_file, parent, inner, depth + 1, placed)

    def _model(
        self,
        model: ET.Element,
        path: Path,
        parent: NDArray,
        name: str | None,
        depth: int,
        *,
        keep_pose: bool,
    ) -> None:
        self._note_unread(model)
        own = model.get("name", "model")
        matrix = parent @ _pose(model.find("pose")) if keep_pose else parent
        label = name or own
        kind = self.classes.get(label) or self.classes.get(own)
        if kind is None:
            self.notes.append(f"model {label!r} (not in the class map: background)")
        elif label in self.names:
            raise FileFormatError(
                f"{path}: two models are called {label!r}; give each <include> its own <name>"
            )
        self.names.add(label)
        heading = _yaw(matrix) + (forward_angle(kind.forward) if kind else 0.0)
        obj = _Object(label if kind else "", kind)
        for link in model.findall("link"):
            self._link(link, path, matrix, obj, heading)
        for nested in model.findall("model"):
            inner = f"{label}::{nested.get('name')}"
            self._model(nested, path, matrix, inner, depth, keep_pose=True)
        for include in model.findall("include"):
            self._include(include, path, matrix, depth, label)  # read_file counts it
        if kind is not None:
            missing = sorted(set(kind.parts) - obj.groups_seen)
            if missing:
                self.notes.append(f"model {label!r}: part groups {missing} in none of its meshes")
        self.pieces += obj.pieces

    def _link(self, link: ET.Element, path: Path, model: NDArray, obj: _Object, heading: float):
        self._note_unread(link)
        matrix = model @ _pose(link.find("pose"))
        for visual in link.findall("visual"):
            self._note_unread(visual)
            geometry = visual.find("geometry")
            if geometry is None:
                continue
            self._note_unread(geometry)
            placed = matrix @ _pose(visual.find("pose"))
            for shape in geometry:
                mesh = self._shape(shape, path, visual.get("name", "visual"))
                if mesh is not None:
                    obj.pieces.append(self._piece(mesh, placed, obj, heading, path))

    # ------------------------------------------------------------------ geometry
    def _shape(self, shape: ET.Element, path: Path, visual: str) -> MeshData | None:
        if shape.tag == "mesh":
            return self._mesh(shape, path)
        primitive = _primitive(shape, path)
        if primitive is None:
            return None
        member = np.ones((1, len(primitive.faces)), dtype=bool)
        return MeshData(
            np.asarray(primitive.vertices, float), np.asarray(primitive.faces), [visual], member
        )

    def _mesh(self, mesh: ET.Element, path: Path) -> MeshData:
        self._note_unread(mesh)
        uri = (mesh.findtext("uri") or "").strip()
        file = self._resolve(uri, path)
        if file is None:
            raise FileFormatError(
                f"{path}: mesh {uri!r} not found on GAZEBO_MODEL_PATH, beside {path.name} "
                "or in its parent folder"
            )
        data = self.cache.read(file)
        scale = _numbers(mesh.findtext("scale") or "1 1 1", 3, f"{path}: <scale>")
        submesh = mesh.find("submesh")
        if submesh is not None:
            self._note_unread(submesh)
            data = _submesh(data, submesh, file)
        return data._replace(vertices=data.vertices * scale)

    def _piece(
        self, mesh: MeshData, matrix: NDArray, obj: _Object, heading: float, path: Path
    ) -> Placed:
        vertices = transform(mesh.vertices, matrix)
        kind = obj.kind
        name, cls = (obj.name, kind.class_name) if kind else ("", BACKGROUND)
        parts = {} if kind is None else kind.parts
        present = [g for g in parts if g in mesh.groups and mesh.member[mesh.groups.index(g)].any()]
        obj.groups_seen.update(present)
        entries = [Entry(groups=[g], instance=name, class_name=cls, part=parts[g]) for g in present]
        centroids = vertices[mesh.faces].mean(axis=1)
        where = f"{path}: {name or 'model'}"
        labels = assign_labels(
            entries, mesh.groups, mesh.member, centroids, where, initial=(name, cls)
        )
        return Placed(vertices, mesh.faces, labels, name, heading)

    # ------------------------------------------------------------------ resolving
    def _resolve(self, uri: str, path: Path) -> Path | None:
        if uri.startswith("model://"):
            rest = uri.removeprefix("model://")
            found = [d / rest for d in self.search if (d / rest).exists()]
            return found[0] if found else None
        plain = uri.removeprefix("file://")
        candidate = Path(plain) if Path(plain).is_absolute() else path.parent / plain
        return candidate if candidate.exists() else None

    def _model_file(self, uri: str, path: Path) -> Path | None:
        folder = self._resolve(uri, path)
        if folder is None or folder.is_file():
            return folder
        config = folder / "model.config"
        if config.is_file():
            named = (_parse(config).findtext("sdf") or "").strip()
            if named and (folder / named).is_file():
                return folder / named
        return folder / "model.sdf" if (folder / "model.sdf").is_file() else None

    # ------------------------------------------------------------------ warnings
    def _note_unread(self, element: ET.Element) -> None:
        read = _READ.get(element.tag, set())
        for child in element:
            if child.tag not in read:
                self.unread[f"{element.tag}/{child.tag}"] += 1
            elif child.tag == "pose" and child.get("relative_to"):
                self.unread["pose@relative_to"] += 1

    def warn(self) -> None:
        parts = [f"{tag} (x{n})" if n > 1 else tag for tag, n in sorted(self.unread.items())]
        said = []
        if parts:
            said.append("not imported: " + ", ".join(parts))
        said += self.notes
        if said:
            warnings.warn(f"{self.path}: " + "; ".join(said), SiteWarning, stacklevel=3)


def _parse(path: Path) -> ET.Element:
    try:
        return ET.parse(path).getroot()
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read ({exc.strerror})") from None
    except ET.ParseError as exc:
        raise FileFormatError(f"{path}: malformed XML ({exc})") from None


def _numbers(text: str, count: int, where: str) -> NDArray[np.float64]:
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        raise FileFormatError(f"{where}: {text.strip()!r} is not {count} numbers") from None
    if len(values) != count or not np.all(np.isfinite(values)):
        raise FileFormatError(f"{where}: {text.strip()!r} is not {count} numbers")
    return values


def _pose(element: ET.Element | None) -> NDArray[np.float64]:
    """The 4x4 transform of an SDF ``<pose>`` (x y z roll pitch yaw, fixed axes)."""
    if element is None or not (element.text or "").strip():
        return np.eye(4)
    values = _numbers(element.text or "", 6, "<pose>")
    if element.get("degrees", "false").lower() == "true":
        values[3:] = np.radians(values[3:])
    return pose_matrix(values[:3], euler_xyz=values[3:])


def _yaw(matrix: NDArray) -> float:
    return math.atan2(matrix[1, 0], matrix[0, 0])


def _submesh(data: MeshData, submesh: ET.Element, file: Path) -> MeshData:
    """Only the faces of one named group, centred on the origin when ``<center>`` says so."""
    name = (submesh.findtext("name") or "").strip()
    if name not in data.groups:
        known = ", ".join(repr(g) for g in data.groups[:12])
        raise FileFormatError(f"{file}: no submesh {name!r}; the mesh has {known}")
    mask = data.member[data.groups.index(name)]
    used, faces = np.unique(data.faces[mask], return_inverse=True)
    vertices = data.vertices[used]
    if (submesh.findtext("center") or "").strip().lower() in ("true", "1"):
        vertices = vertices - (vertices.min(axis=0) + vertices.max(axis=0)) / 2
    return MeshData(vertices, faces.reshape(-1, 3), data.groups, data.member[:, mask])


def _primitive(shape: ET.Element, path: Path) -> trimesh.Trimesh | None:
    where = f"{path}: <{shape.tag}>"
    if shape.tag == "box":
        size = _numbers(shape.findtext("size") or "", 3, f"{where} <size>")
        return trimesh.creation.box(extents=size)
    if shape.tag == "cylinder":
        radius = _numbers(shape.findtext("radius") or "", 1, f"{where} <radius>")[0]
        length = _numbers(shape.findtext("length") or "", 1, f"{where} <length>")[0]
        return trimesh.creation.cylinder(radius=radius, height=length, sections=24)
    if shape.tag == "sphere":
        radius = _numbers(shape.findtext("radius") or "", 1, f"{where} <radius>")[0]
        return trimesh.creation.icosphere(subdivisions=2, radius=radius)
    return None
