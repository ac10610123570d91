"""Site files: several labelled meshes, each placed by position, yaw and scale, in one world.

A site file (YAML or JSON) names its meshes relative to itself::

    format: seminspect-site
    version: 1
    name: gazebo-lot
    ground: {margin: 8}           # a ground plane under everything, 8 m around it
    start: {position: [-12, 0, 0], yaw: 0}
    meshes:
      - path: prius_hybrid/Hybrid.obj
        class: car
        instance: prius           # kept exactly as written (no renumbering)
        scale: 0.01
        forward: -y               # the mesh's front is its -y side
        position: [0, 0, 0]
        yaw: 0                    # the front faces +x
        parts: {Hybrid: body, Hybrid_Windows: windows, Wheels_Rear: back-wheels}
    sdf: lot.world                # optional: a Gazebo world or model to import as well
    classes:                      # what the SDF's models are (see worlds.sdf)
      prius_hybrid: {class: car, forward: -y, parts: {Hybrid: body}}

A mesh's geometry is scaled, turned Z-up (``up: y``), turned so that its ``forward`` axis
points along +x, then turned by ``yaw`` and moved to ``position``: ``yaw`` is the direction the
object's front faces, counter-clockwise from +x. ``parts`` maps mesh groups to part names;
``labels`` instead takes the entries of a labels file (``worlds.user``), whose ``box`` is in
the object's frame (after scale, up and forward) and which inherit the mesh's instance and
class unless they name their own. Every face of a mesh belongs to its object (part ``""``
unless a part or entry names one); a mesh without ``instance`` is background geometry.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_json, read_yaml
from seminspect.worlds.labelling import Box, Entry, Ground, Start, assign_labels, validated
from seminspect.worlds.meshes import Y_UP, MeshData
from seminspect.worlds.pieces import Layout, Placed, assemble, transform
from seminspect.worlds.sdf import ClassMap, MeshCache, forward_angle, load_sdf_pieces
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.world import World

SITE_FORMAT = "seminspect-site"
SITE_SUFFIXES = (".json", ".yaml", ".yml")
Forward = Literal["x", "-x", "y", "-y"]


class _Mesh(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True)

    path: str
    class_name: str = Field(alias="class")
    instance: str | None = None
    labels: list[Entry] | None = None
    parts: dict[str, str] | None = None
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    scale: float | tuple[float, float, float] = 1.0
    up: Literal["z", "y"] = "z"
    forward: Forward = "x"

    @field_validator("scale")
    @classmethod
    def _positive(cls, scale: float | tuple[float, ...]) -> float | tuple[float, ...]:
        if min(np.atleast_1d(scale)) <= 0:
            raise ValueError("a scale must be positive")
        return scale

    @field_validator("parts")
    @classmethod
    def _named(cls, parts: dict[str, str] | None) -> dict[str, str] | None:
        if parts is not None and not all(parts.values()):
            raise ValueError("every part needs a name")
        return parts


class _Site(BaseModel):
    model_config = ConfigDict(extra="forbid")

    format: Literal["seminspect-site"]
    version: Literal[1]
    name: str = "site"
    seed: int = Field(0, ge=0)
    ground: Ground | None = None
    bounds: Box | None = None
    start: Start | None = None
    meshes: list[_Mesh] = []
    sdf: str | None = None
    classes: ClassMap = {}
    metadata: dict[str, Any] = {}


def _read_document(path: Path) -> Any:
    is_yaml = path.suffix.lower() in (".yaml", ".yml")
    return read_yaml(path) if is_yaml else read_json(path)


def is_site_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a YAML or JSON file whose ``format`` is ``seminspect-site``."""
    source = Path(path)
    if not source.is_file() or source.suffix.lower() not in SITE_SUFFIXES:
        return False
    document = _read_document(source)
    return isinstance(document, dict) and document.get("format") == SITE_FORMAT


def read_site(path: Path) -> _Site:
    """The validated site document, or a one-line error naming the file and the key."""
    document = _read_document(path)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a mapping at the top level")
    site = validated(_Site, document, path)
    for index, mesh in enumerate(site.meshes):
        if mesh.labels is not None and mesh.parts is not None:
            raise FileFormatError(f"{path}: meshes[{index}]: give 'labels' or 'parts', not both")
    return site


def missing_files(path: str | os.PathLike[str]) -> list[str]:
    """One line for each mesh or SDF file a site file names that does not exist."""
    source = Path(path)
    site = read_site(source)
    named = [(f"meshes[{i}].path", m.path) for i, m in enumerate(site.meshes)]
    named += [("sdf", site.sdf)] if site.sdf else []
    return [
        f"{source}: {key}: no such file {source.parent / value}"
        for key, value in named
        if not (source.parent / value).is_file()
    ]


def load_site(path: str | os.PathLike[str]) -> World:
    """The world a site file describes (see the module's documentation)."""
    source = Path(path)
    site = read_site(source)
    owners = _owners(site.meshes, source)
    cache = MeshCache()
    pieces = [
        _place(mesh, f"{source}: meshes[{index}]", source, cache)
        for index, mesh in enumerate(site.meshes)
    ]
    if site.sdf:
        imported = load_sdf_pieces(source.parent / site.sdf, site.classes, cache)
        for piece in imported:
            if piece.name in owners:
                raise FileFormatError(
                    f"{source}: the SDF's object {piece.name!r} has the name of "
                    f"{owners[piece.name]}; rename one of them"
                )
        pieces += imported
    layout = Layout(site.name, site.seed, site.ground, site.bounds, site.start)
    return assemble(pieces, layout, dict(site.metadata), str(source))


def _owners(meshes: list[_Mesh], source: Path) -> dict[str, str]:
    """Which mesh each object name belongs to; two meshes with one name are refused."""
    owners: dict[str, str] = {}
    for index, mesh in enumerate(meshes):
        if mesh.instance is None:
            continue
        if mesh.instance in owners:
            raise FileFormatError(
                f"{source}: meshes[{index}]: instance {mesh.instance!r} is already "
                f"{owners[mesh.instance]}'s; each object needs its own name"
            )
        owners[mesh.instance] = f"meshes[{index}]"
    return owners


def _place(mesh: _Mesh, where: str, source: Path, cache: MeshCache) -> Placed:
    path = source.parent / mesh.path
    if not path.is_file():
        raise FileFormatError(f"{where}.path: no such file {path}")
    data = cache.read(path)
    local = _local_vertices(data, mesh)
    centroids = local[data.faces].mean(axis=1)
    key = "parts" if mesh.parts is not None else "labels"
    initial = (mesh.instance or "", mesh.class_name)
    entries = _entries(mesh)
    labels = assign_labels(
        entries, data.groups, data.member, centroids, f"{where}.{key}", initial=initial
    )
    world = transform(local, pose_matrix(mesh.position, mesh.yaw))
    return Placed(world, data.faces, labels, mesh.instance or "", mesh.yaw)


def _local_vertices(data: MeshData, mesh: _Mesh) -> NDArray[np.float64]:
    """The mesh in its object's frame: scaled, Z-up, its front along +x."""
    points = data.vertices * np.broadcast_to(np.asarray(mesh.scale, float), (3,))
    if mesh.up == "y":
        points = points @ Y_UP
    return transform(points, pose_matrix(yaw=-forward_angle(mesh.forward)))


def _entries(mesh: _Mesh) -> list[Entry]:
    """The labels entries of a mesh: its part map as entries, or its own entries, which
    inherit the mesh's instance and class unless they name their own."""
    own = {"instance": mesh.instance, "class_name": mesh.class_name}
    if mesh.parts is not None:
        return [Entry(groups=[group], part=part, **own) for group, part in mesh.parts.items()]
    return [_inherit(entry, own) for entry in mesh.labels or []]


def _inherit(entry: Entry, own: dict[str, Any]) -> Entry:
    """An entry naming neither instance nor class labels its mesh's object."""
    if entry.instance or "class_name" in entry.model_fields_set:
        return entry
    return entry.model_copy(update=own)
