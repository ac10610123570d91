"""The labelled world: one triangle mesh whose every face knows its instance, class and part.

Ground-truth objects (:class:`InstanceInfo`) carry what evaluation needs: name, class, centroid,
top-down footprint, box, volume and parts. Ray casting and collision queries are built lazily and
cached on the world, so a world that is only drawn never pays for them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import shapely
import trimesh
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import Polygon

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.geometry.transforms import as_point
from seminspect.worlds.collision import CollisionField, CollisionMode
from seminspect.worlds.raycast import RayCaster

#: Class of faces that belong to no object (user meshes with unlabelled faces).
BACKGROUND = "background"
#: Class of the floor a ground robot walks on; the ground-robot collision grid ignores it.
GROUND = "ground"


@dataclass(frozen=True)
class InstanceInfo:
    """Ground truth of one object, for evaluation (never shown to the robot).

    Attributes:
        id: instance id (> 0) used in ``World.face_instance`` and in frames.
        name: ground-truth name, class plus a 1-based number (``car-3``).
        class_name: semantic class (``car``, ``truck``, ``building``, ...).
        centroid: area-weighted centroid of the object's surface (metres).
        footprint: top-down convex hull of the object (shapely Polygon).
        bbox_min, bbox_max: axis-aligned box (metres).
        volume: enclosed volume (m^3); the convex hull's when the surface is not closed.
        height: vertical extent of the box (metres).
        parts: names of the parts the object's faces carry (sorted).
    """

    id: int
    name: str
    class_name: str
    centroid: NDArray[np.float64]
    footprint: Polygon
    bbox_min: NDArray[np.float64]
    bbox_max: NDArray[np.float64]
    volume: float
    height: float
    parts: list[str]


@dataclass(eq=False)
class World:
    """A labelled triangle-mesh world.

    Attributes:
        name: world name (``city``, a user file's name, ...).
        mesh: the whole world as one mesh, ground included.
        face_instance: ``int32`` instance id per face; 0 is ground or background.
        face_class: ``int16`` index into ``class_names`` per face.
        face_part: ``int16`` index into ``part_names`` per face; index 0 is ``""`` (no part).
        class_names: class vocabulary; ``class_names[0]`` is ``"background"``.
        part_names: part vocabulary; ``part_names[0]`` is ``""``.
        instances: ground truth per instance id.
        bounds: ``(2, 3)`` box the robot may move in (metres).
        start_position: a free point on the ground where missions start.
        start_yaw: heading at the start (radians).
        seed: the seed the world was generated from.
        metadata: generator, scenario, options, ground height, licences, ...
    """

    name: str
    mesh: trimesh.Trimesh
    face_instance: NDArray[np.int32]
    face_class: NDArray[np.int16]
    face_part: NDArray[np.int16]
    class_names: list[str]
    part_names: list[str]
    instances: dict[int, InstanceInfo]
    bounds: NDArray[np.float64]
    start_position: NDArray[np.float64]
    start_yaw: float = 0.0
    seed: int = 0
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        count = len(self.mesh.faces)
        for label, array in (
            ("face_instance", self.face_instance),
            ("face_class", self.face_class),
            ("face_part", self.face_part),
        ):
            if array.shape != (count,):
                raise InvalidInputError(f"{label} has {array.shape} entries for {count} faces")
        if not self.part_names or self.part_names[0] != "":
            raise InvalidInputError('part_names[0] must be "" (no part)')
        if count and (self.face_class.max() >= len(self.class_names) or self.face_class.min() < 0):
            raise InvalidInputError("face_class holds an index outside class_names")
        if count and (self.face_part.max() >= len(self.part_names) or self.face_part.min() < 0):
            raise InvalidInputError("face_part holds an index outside part_names")
        self.bounds = np.asarray(self.bounds, dtype=np.float64).reshape(2, 3)
        if np.any(self.bounds[1] <= self.bounds[0]):
            raise InvalidInputError(f"world bounds are empty: {self.bounds.tolist()}")
        self.start_position = as_point(self.start_position, "world start position")
        if not math.isfinite(self.start_yaw):
            raise InvalidInputError(f"start yaw must be finite, got {self.start_yaw}")

    # ----------------------------------------------------------------- vocabulary and truth
    def class_id(self, name: str) -> int:
        """Index of a class name (raises :class:`UnknownNameError`)."""
        try:
            return self.class_names.index(name)
        except ValueError:
            raise unknown_name("class", name, self.class_names) from None

    def part_id(self, name: str) -> int:
        """Index of a part name (raises :class:`UnknownNameError`)."""
        try:
            return self.part_names.index(name)
        except ValueError:
            raise unknown_name("part", name, self.part_names[1:]) from None

    def instances_of(self, *class_names: str) -> list[InstanceInfo]:
        """Ground-truth objects of the given classes (all objects when none are given)."""
        wanted = set(class_names)
        return [i for i in self.instances.values() if not wanted or i.class_name in wanted]

    def instance_named(self, name: str) -> InstanceInfo:
        """The object called ``name`` (``car-3``)."""
        for info in self.instances.values():
            if info.name == name:
                return info
        raise unknown_name("instance", name, (i.name for i in self.instances.values()))

    @property
    def ground_z(self) -> float:
        """Height of the ground plane (metres)."""
        return float(self.metadata.get("ground_z", self.bounds[0, 2]))

    # ----------------------------------------------------------------- cached geometry
    @cached_property
    def triangles(self) -> NDArray[np.float64]:
        """``(F, 3, 3)`` triangle corners."""
        return np.asarray(self.mesh.vertices)[np.asarray(self.mesh.faces)]

    @cached_property
    def face_normals(self) -> NDArray[np.float64]:
        """Unit normal per face (zero for degenerate faces)."""
        return np.asarray(self.mesh.face_normals, dtype=np.float64)

    @cached_property
    def raycaster(self) -> RayCaster:
        """Embree scene of the mesh, built on first use."""
        return RayCaster(self.mesh.vertices, self.mesh.faces)

    @cached_property
    def collision(self) -> CollisionField:
        """Distance grids for clearance queries, each built on first use."""
        ground = (
            self.face_class == self.class_names.index(GROUND)
            if GROUND in self.class_names
            else np.zeros(len(self.face_class), dtype=bool)
        )
        low, high = self.metadata.get("ground_band", (0.15, 2.0))
        return CollisionField(
            self.triangles,
            self.face_instance,
            ground,
            self.bounds,
            ground_z=self.ground_z,
            band=(low, high),
        )

    def clearance(self, points: ArrayLike, mode: CollisionMode = "aerial") -> NDArray[np.float64]:
        """Conservative distance of each point to the nearest surface; see ``worlds.collision``.

        ``mode="ground"`` measures horizontally to obstacles a legged robot cannot step over
        (the ground plane excluded); ``mode="aerial"`` measures in 3D to every surface.
        """
        return self.collision.clearance(points, mode)

    def is_free(
        self, points: ArrayLike, radius: float, mode: CollisionMode = "aerial"
    ) -> NDArray[np.bool_]:
        """Whether a body of ``radius`` fits at each point without touching a surface."""
        return self.collision.is_free(points, radius, mode)

    def segment_is_free(
        self, start: ArrayLike, end: ArrayLike, radius: float, mode: CollisionMode = "aerial"
    ) -> bool:
        """Whether a body of ``radius`` can move along the straight segment."""
        return self.collision.segment_is_free(start, end, radius, mode)

    def summary(self) -> dict[str, Any]:
        """A short description for listings and reports."""
        counts: dict[str, int] = {}
        for info in self.instances.values():
            counts[info.class_name] = counts.get(info.class_name, 0) + 1
        return {
            "name": self.name,
            "scenario": self.metadata.get("scenario"),
            "seed": self.seed,
            "faces": len(self.mesh.faces),
            "size_m": (self.bounds[1] - self.bounds[0]).round(2).tolist(),
            "objects": dict(sorted(counts.items())),
        }


def describe_instances(
    mesh: trimesh.Trimesh,
    *,
    face_instance: NDArray[np.int32],
    face_class: NDArray[np.int16],
    face_part: NDArray[np.int16],
    class_names: list[str],
    part_names: list[str],
    names: dict[int, str],
) -> dict[int, InstanceInfo]:
    """Compute the ground truth of every instance id > 0 from the labelled faces."""
    vertices = np.asarray(mesh.vertices)
    faces = np.asarray(mesh.faces)
    order = np.argsort(face_instance, kind="stable")
    ids, starts = np.unique(face_instance[order], return_index=True)
    ends = np.append(starts[1:], len(order))
    result: dict[int, InstanceInfo] = {}
    for inst, lo, hi in zip(ids.tolist(), starts, ends, strict=True):
        if inst == 0:
            continue
        own = order[lo:hi]
        classes = np.unique(face_class[own])
        if len(classes) != 1:
            found = [class_names[c] for c in classes]
            raise InvalidInputError(f"instance {names.get(inst, inst)} mixes classes {found}")
        name = names.get(inst, f"{class_names[classes[0]]}-{inst}")
        parts = sorted({part_names[p] for p in np.unique(face_part[own]) if p})
        result[inst] = _describe_one(
            vertices,
            faces[own],
            inst=inst,
            name=name,
            class_name=class_names[classes[0]],
            parts=parts,
        )
    return result


def _describe_one(
    vertices: NDArray, faces: NDArray, *, inst: int, name: str, class_name: str, parts: list[str]
) -> InstanceInfo:
    tri = vertices[faces]
    areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    used = vertices[np.unique(faces)]
    tri_centres = tri.mean(axis=1)
    total = float(areas.sum())
    centroid = (
        (tri_centres * areas[:, None]).sum(axis=0) / total if total > 0 else used.mean(axis=0)
    )
    lo, hi = used.min(axis=0), used.max(axis=0)
    return InstanceInfo(
        id=int(inst),
        name=name,
        class_name=class_name,
        centroid=centroid,
        footprint=_footprint(used[:, :2]),
        bbox_min=lo,
        bbox_max=hi,
        volume=_volume(vertices, faces),
        height=float(hi[2] - lo[2]),
        parts=parts,
    )


def _footprint(xy: NDArray[np.float64]) -> Polygon:
    hull = shapely.MultiPoint(xy).convex_hull
    if not isinstance(hull, Polygon):  # a flat or degenerate object: give it a sliver of area
        hull = hull.buffer(0.01)
    return hull


def _volume(vertices: NDArray, faces: NDArray) -> float:
    """Enclosed volume of closed, outward-oriented surfaces; else the convex hull's volume.

    Touching solids (a car's body sections) share faces with opposite orientation, which
    cancel in the divergence-theorem sum, so a union of closed pieces counts once.
    """
    merged = trimesh.Trimesh(vertices, faces, process=True)
    if _is_closed(np.asarray(merged.faces)):
        return float(abs(merged.volume))
    return float(merged.convex_hull.volume) if len(merged.vertices) >= 4 else 0.0


def _is_closed(faces: NDArray) -> bool:
    """Whether every edge is walked as often in one direction as in the other."""
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    sign = np.where(directed[:, 0] < directed[:, 1], 1, -1)
    keys, inverse = np.unique(np.sort(directed, axis=1), axis=0, return_inverse=True)
    balance = np.bincount(inverse.ravel(), weights=sign, minlength=len(keys))
    return bool(len(faces)) and not np.any(balance)
