"""Assembling a :class:`World` from labelled pieces.

Generators and user loaders add pieces (closed solids with per-face part labels) or whole
meshes, each under an instance and a class; :meth:`WorldBuilder.build` concatenates them into one
mesh with per-face label arrays and computes the ground truth of every instance.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.worlds.shapes import Piece
from seminspect.worlds.world import BACKGROUND, GROUND, World, describe_instances


def _per_face(value: str | Sequence[str], count: int, what: str) -> list[str]:
    labels = [value] * count if isinstance(value, str) else list(value)
    if len(labels) != count:
        raise InvalidInputError(f"{len(labels)} {what} labels for {count} faces")
    return labels


class WorldBuilder:
    """Collects labelled geometry; instance ids are handed out from 1 in order of creation."""

    def __init__(self, name: str, seed: int = 0) -> None:
        self.name = name
        self.seed = seed
        self.class_names: list[str] = [BACKGROUND, GROUND]
        self.part_names: list[str] = [""]
        self._names: dict[int, str] = {}
        self._class_of: dict[int, str] = {}
        self._per_class: dict[str, int] = {}
        self._vertices: list[NDArray[np.float64]] = []
        self._faces: list[NDArray[np.int64]] = []
        self._labels: list[tuple[NDArray[np.int32], NDArray[np.int16], NDArray[np.int16]]] = []
        self._vertex_count = 0

    def _index(self, vocabulary: list[str], name: str) -> int:
        if name not in vocabulary:
            vocabulary.append(name)
        return vocabulary.index(name)

    def new_instance(self, class_name: str, name: str | None = None) -> int:
        """Register an object; its default name is the class and a per-class number."""
        if class_name in (BACKGROUND, GROUND):
            raise InvalidInputError(f"class {class_name!r} is reserved for unlabelled geometry")
        taken = set(self._names.values())
        if name is None:
            number = self._per_class.get(class_name, 0) + 1
            while f"{class_name}-{number}" in taken:
                number += 1
            self._per_class[class_name] = number
            name = f"{class_name}-{number}"
        elif name in taken:
            raise InvalidInputError(f"two objects are called {name!r}")
        instance = len(self._names) + 1
        self._names[instance] = name
        self._class_of[instance] = class_name
        return instance

    def add_faces(
        self,
        vertices: ArrayLike,
        faces: ArrayLike,
        class_name: str | Sequence[str],
        parts: str | Sequence[str] = "",
        instance: int | ArrayLike = 0,
    ) -> None:
        """Add triangles with their class, part and instance, one for all faces or one each.

        Only the vertices the faces use are kept, and faces keep their order.
        """
        verts = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        tris = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        count = len(tris)
        classes = _per_face(class_name, count, "class")
        part_list = _per_face(parts, count, "part")
        instances = np.broadcast_to(np.asarray(instance, dtype=np.int32), (count,))
        for inst, cls in set(zip(instances.tolist(), classes, strict=True)):
            if inst and self._class_of.get(inst) != cls:
                raise InvalidInputError(f"object {self._names.get(inst, inst)} is not a {cls!r}")
        used, tris = np.unique(tris, return_inverse=True)
        class_index = {c: self._index(self.class_names, c) for c in dict.fromkeys(classes)}
        part_index = {p: self._index(self.part_names, p) for p in dict.fromkeys(part_list)}
        self._vertices.append(verts[used])
        self._faces.append(tris.reshape(-1, 3) + self._vertex_count)
        self._labels.append(
            (
                instances.copy(),
                np.array([class_index[c] for c in classes], dtype=np.int16),
                np.array([part_index[p] for p in part_list], dtype=np.int16),
            )
        )
        self._vertex_count += len(used)

    def add_piece(self, piece: Piece, class_name: str, instance: int = 0) -> None:
        """Add one labelled solid."""
        self.add_faces(piece.vertices, piece.faces, class_name, piece.labels, instance)

    def add_object(
        self,
        pieces: Sequence[Piece],
        class_name: str,
        transform: ArrayLike | None = None,
        name: str | None = None,
    ) -> int:
        """Add a new object made of ``pieces`` (in object coordinates) and return its id."""
        instance = self.new_instance(class_name, name)
        matrix = np.eye(4) if transform is None else np.asarray(transform, dtype=np.float64)
        for piece in pieces:
            self.add_piece(piece.transformed(matrix), class_name, instance)
        return instance

    def add_ground(self, lower_xy: ArrayLike, upper_xy: ArrayLike, z: float = 0.0) -> None:
        """A flat rectangle of class ``ground`` facing up."""
        (x0, y0), (x1, y1) = np.asarray(lower_xy, float), np.asarray(upper_xy, float)
        corners = [(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]
        self.add_faces(corners, [(0, 1, 2), (0, 2, 3)], GROUND)

    def instance_names(self) -> list[str]:
        """Names of the objects registered so far, in id order."""
        return list(self._names.values())

    def build(
        self,
        bounds: ArrayLike,
        start_position: ArrayLike,
        start_yaw: float = 0.0,
        metadata: dict[str, Any] | None = None,
    ) -> World:
        """Concatenate everything into a :class:`World`."""
        if not self._faces:
            raise InvalidInputError(f"world {self.name!r} has no geometry")
        mesh = trimesh.Trimesh(
            np.vstack(self._vertices), np.vstack(self._faces), process=False, validate=False
        )
        face_instance, face_class, face_part = (
            np.concatenate(column) for column in zip(*self._labels, strict=True)
        )
        instances = describe_instances(
            mesh,
            face_instance=face_instance,
            face_class=face_class,
            face_part=face_part,
            class_names=self.class_names,
            part_names=self.part_names,
            names=self._names,
        )
        return World(
            name=self.name,
            mesh=mesh,
            face_instance=face_instance,
            face_class=face_class,
            face_part=face_part,
            class_names=list(self.class_names),
            part_names=list(self.part_names),
            instances=instances,
            bounds=np.asarray(bounds, dtype=np.float64),
            start_position=np.asarray(start_position, dtype=np.float64),
            start_yaw=float(start_yaw),
            seed=self.seed,
            metadata=dict(metadata or {}),
        )
