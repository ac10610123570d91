"""Labelling faces of a mesh (instance, class, part) and finishing a world around them: the
part that the single-mesh labels files of ``worlds.user`` and the site files of
``worlds.site`` share."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.collision import check_grid_sizes
from seminspect.worlds.world import BACKGROUND, World

_Document = TypeVar("_Document", bound=BaseModel)


def validated(model: type[_Document], document: Any, path: Path) -> _Document:
    """``document`` read into ``model``, or a ``FileFormatError`` naming the file, the key and
    what is wrong with its value (the first problem found)."""
    try:
        return model.model_validate(document)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "document"
        raise FileFormatError(f"{path}: {where}: {first['msg']}") from None


Box = tuple[tuple[float, float, float], tuple[float, float, float]]
#: How to shrink a world too large for its collision grids.
SIZE_FIX = (
    "is its scale right? 'scale: {scale:g}' turns mesh units into metres: use a smaller scale "
    "or tighter 'bounds:'"
)


class Entry(BaseModel):
    """One labels entry: which faces (groups, face ranges, a box) get which labels."""

    model_config = ConfigDict(extra="forbid", populate_by_name=True)

    groups: list[str] | None = None
    faces: list[tuple[int, int]] | None = None
    box: Box | None = None
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


class Start(BaseModel):
    model_config = ConfigDict(extra="forbid")

    position: tuple[float, float, float]
    yaw: float = 0.0


class Ground(BaseModel):
    model_config = ConfigDict(extra="forbid")

    margin: float = Field(10.0, ge=0, le=1e4)
    #: Height of the plane; the mesh's lowest point when not given.
    z: float | None = None


#: Per-face labels: instance names ("" for background), class names and part names.
FaceLabels = tuple[NDArray[np.object_], NDArray[np.object_], NDArray[np.object_]]


def select_faces(
    entry: Entry, groups: list[str], member: NDArray, centroids: NDArray, where: str
) -> NDArray[np.bool_]:
    """The faces one entry selects (all of them when it names no group and no range)."""
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


def assign_labels(
    entries: Sequence[Entry],
    groups: list[str],
    member: NDArray,
    centroids: NDArray,
    where: str,
    *,
    initial: tuple[str, str] = ("", BACKGROUND),
) -> FaceLabels:
    """Per-face (instance name, class, part) after applying every entry in order, starting
    from ``initial`` (instance, class) on every face."""
    count = member.shape[1]
    instance = np.full(count, initial[0], dtype=object)
    classes = np.full(count, initial[1], dtype=object)
    parts = np.full(count, "", dtype=object)
    for index, entry in enumerate(entries):
        here = f"{where}[{index}]"
        chosen = select_faces(entry, groups, member, centroids, here)
        if not chosen.any():
            raise FileFormatError(f"{here}: selects no faces")
        instance[chosen] = entry.instance or ""
        classes[chosen] = entry.class_name
        parts[chosen] = entry.part
    return instance, classes, parts


def add_labelled(
    builder: WorldBuilder, vertices: NDArray, faces: NDArray, labels: FaceLabels
) -> None:
    """Add every face in file order; objects are numbered in order of their first face and
    keep the names the labels give them."""
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


def finish_world(
    builder: WorldBuilder,
    vertices: NDArray,
    *,
    ground: Ground | None,
    bounds: Box | None,
    start: Start | None,
    metadata: dict[str, Any],
    fix: str,
) -> World:
    """Add the optional ground plane, then bound, start and build the world.

    The default bounds are the mesh box (plus the ground) and 2 m above it; the default start
    lies 1 m inside the lower corner, on the ground (the mesh's lowest point unless the ground
    plane is given a height).
    """
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    floor = float(lo[2])
    if ground is not None:
        floor = floor if ground.z is None else float(ground.z)
        margin = np.array([ground.margin, ground.margin, 0.0])
        builder.add_ground(lo[:2] - margin[:2], hi[:2] + margin[:2], floor)
        lo, hi = lo - margin, hi + margin
        lo[2], hi[2] = min(lo[2], floor), max(hi[2], floor)
    box = np.array(bounds or [lo, hi + np.array([0.0, 0.0, 2.0])])
    check_grid_sizes(box, fix=fix)
    begin = start or Start(position=(box[0, 0] + 1.0, box[0, 1] + 1.0, floor))
    # the ground is the mesh's lowest point unless the file says otherwise (a saved world)
    return builder.build(box, begin.position, begin.yaw, {"ground_z": floor, **metadata})
