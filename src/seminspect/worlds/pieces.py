"""Labelled meshes placed in a site, and the world they make together.

A site file's meshes and an SDF file's visuals both become :class:`Placed` pieces: world
vertices with per-face labels, and the heading of the object they belong to. The heading of
an object is the direction its front faces, in radians counter-clockwise from +x; the world
keeps it under ``metadata["headings"]`` so that sizes and checks can be taken along it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.labelling import Box, FaceLabels, Ground, Start, add_labelled, finish_world
from seminspect.worlds.world import InstanceInfo, World

SITE_SIZE_FIX = "are the meshes' scales right? use a smaller 'scale:' or tighter 'bounds:'"


@dataclass(frozen=True)
class Placed:
    """One labelled mesh in world coordinates; ``name`` is its object's ('' for background)."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    labels: FaceLabels
    name: str
    heading: float


@dataclass(frozen=True)
class Layout:
    """What a site says besides its pieces: name, seed, ground, bounds and start."""

    name: str = "site"
    seed: int = 0
    ground: Ground | None = None
    bounds: Box | None = None
    start: Start | None = None


def transform(points: NDArray[np.float64], matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """``points`` moved by a 4x4 transform."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def assemble(pieces: list[Placed], layout: Layout, metadata: dict[str, Any], source: str) -> World:
    """One world from every piece, in order: objects are numbered in the order they first
    appear and keep their names."""
    if not pieces:
        raise FileFormatError(f"{source}: the site places no meshes")
    offsets = np.cumsum([0] + [len(p.vertices) for p in pieces[:-1]])
    vertices = np.vstack([p.vertices for p in pieces])
    faces = np.vstack([p.faces + offset for p, offset in zip(pieces, offsets, strict=True)])
    labels = tuple(np.concatenate([p.labels[k] for p in pieces]) for k in range(3))
    headings = {p.name: float(p.heading) for p in pieces if p.name}
    builder = WorldBuilder(layout.name, layout.seed)
    try:
        add_labelled(builder, vertices, faces, labels)  # type: ignore[arg-type]
        return finish_world(
            builder,
            vertices,
            ground=layout.ground,
            bounds=layout.bounds,
            start=layout.start,
            metadata={**metadata, "headings": headings, "source": source},
            fix=SITE_SIZE_FIX,
        )
    except InvalidInputError as exc:
        raise FileFormatError(f"{source}: {exc}") from None


def object_vertices(world: World, info: InstanceInfo) -> NDArray[np.float64]:
    """The vertices of one object's faces."""
    faces = np.asarray(world.mesh.faces)[world.face_instance == info.id]
    return np.asarray(world.mesh.vertices)[np.unique(faces)]


def size_along(world: World, info: InstanceInfo, heading: float) -> tuple[float, float]:
    """(length, width) of an object: its extent along ``heading`` and across it."""
    xy = object_vertices(world, info)[:, :2]
    forward = np.array([math.cos(heading), math.sin(heading)])
    side = np.array([-forward[1], forward[0]])
    along, across = xy @ forward, xy @ side
    return float(np.ptp(along)), float(np.ptp(across))


def heading_of(world: World, name: str) -> float | None:
    """The heading a site gave an object, or None for objects of generated worlds."""
    value = world.metadata.get("headings", {}).get(name)
    return None if value is None else float(value)
