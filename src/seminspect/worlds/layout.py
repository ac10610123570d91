"""Placing vehicles so that a ground robot can inspect each one.

Every vehicle keeps a clear gap to every other vehicle and to every obstacle footprint, so that a
robot of radius 0.4 m can drive a full ring around it at a 2-3 m viewing distance, and vehicle
centres stay more than 8 m apart (the scene graph merges target detections within
``d_check^T = 4`` m, 000 Table 1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Point, Polygon
from shapely.geometry.base import BaseGeometry

from seminspect.core.errors import InvalidInputError
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.vehicles import vehicle_pieces, vehicle_size

#: Clear gap between vehicle footprints and from obstacle footprints (metres).
VEHICLE_GAP = 7.0
#: Vehicle centres are at least this far apart (metres).
MIN_CENTRE_DISTANCE = 8.0


@dataclass(frozen=True)
class Slot:
    """A candidate parking pose: centre and heading of a vehicle's footprint."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class Placement:
    """A placed vehicle: class, pose, size scale and top-down footprint."""

    class_name: str
    slot: Slot
    scale: tuple[float, float, float]
    footprint: Polygon


def footprint(x: float, y: float, yaw: float, length: float, width: float) -> Polygon:
    """The rotated rectangle a vehicle covers on the ground."""
    c, s = math.cos(yaw), math.sin(yaw)
    corners = [(+length / 2, +width / 2), (-length / 2, +width / 2), (-length / 2, -width / 2)]
    corners.append((+length / 2, -width / 2))
    return Polygon([(x + c * u - s * v, y + s * u + c * v) for u, v in corners])


def place_vehicles(
    rng: np.random.Generator,
    slots: Sequence[Slot],
    count: int,
    *,
    truck_share: float,
    obstacles: BaseGeometry,
    keep_clear: BaseGeometry,
    gap: float = VEHICLE_GAP,
) -> list[Placement]:
    """Fill randomly chosen slots with cars and trucks, keeping the clearances above.

    Args:
        rng: the generator's vehicle stream.
        slots: candidate poses, tried in random order.
        count: how many vehicles to place.
        truck_share: probability that a vehicle is a truck.
        obstacles: footprints (buildings, walls) vehicles must stay ``gap`` away from.
        keep_clear: area that must stay free of vehicles (the world's outside, the start).
        gap: clear distance between footprints.
    """
    placed: list[Placement] = []
    for index in rng.permutation(len(slots)):
        if len(placed) == count:
            break
        slot = slots[int(index)]
        class_name = "truck" if rng.random() < truck_share else "car"
        scale = tuple(float(v) for v in rng.uniform(0.96, 1.04, size=3))
        length, width, _ = (a * b for a, b in zip(vehicle_size(class_name), scale, strict=True))
        shape = footprint(slot.x, slot.y, slot.yaw, length, width)
        if _fits(shape, Point(slot.x, slot.y), placed, (obstacles, keep_clear), gap):
            placed.append(Placement(class_name, slot, scale, shape))  # type: ignore[arg-type]
    if len(placed) < count:
        raise InvalidInputError(
            f"only {len(placed)} of {count} vehicles fit with a {gap} m clearance; "
            "ask for fewer vehicles"
        )
    return placed


def _fits(
    shape: Polygon,
    centre: Point,
    placed: Sequence[Placement],
    areas: tuple[BaseGeometry, BaseGeometry],
    gap: float,
) -> bool:
    """Whether a footprint keeps its gaps; ``areas`` are (obstacles, keep-clear area)."""
    obstacles, keep_clear = areas
    if shape.intersects(keep_clear):
        return False
    if not obstacles.is_empty and shape.distance(obstacles) < gap:
        return False
    return all(
        shape.distance(other.footprint) >= gap
        and centre.distance(Point(other.slot.x, other.slot.y)) > MIN_CENTRE_DISTANCE
        for other in placed
    )


def add_vehicles(builder: WorldBuilder, placements: Sequence[Placement]) -> None:
    """Add the placed vehicles to a world, numbered per class in placement order."""
    for p in placements:
        pieces = vehicle_pieces(p.class_name, np.asarray(p.scale))
        builder.add_object(pieces, p.class_name, pose_matrix((p.slot.x, p.slot.y, 0.0), p.slot.yaw))


def outside_of(lower: Sequence[float], upper: Sequence[float], margin: float) -> BaseGeometry:
    """Everything farther out than ``margin`` inside the rectangle's border."""
    outer = shapely.box(lower[0] - 1e3, lower[1] - 1e3, upper[0] + 1e3, upper[1] + 1e3)
    inner = shapely.box(lower[0] + margin, lower[1] + margin, upper[0] - margin, upper[1] - margin)
    return outer.difference(inner)
