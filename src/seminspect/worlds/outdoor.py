"""The outdoor terrain world of 001 Sec IV: sidewalks, grass and asphalt with trees and cars.

001 maps a campus section with sidewalks, lawns, roads and parking, trees and parked cars. This
world lays the same out on flat ground: a road (``asphalt``) with a ``sidewalk`` on each side,
``grass`` everywhere else and, in the ``block`` scenario, a footpath branching off the north
sidewalk and a parking lot. Every ground face carries its terrain class (instance 0, like the
ground of the other worlds), so a camera sees terrain segments; trees (parts ``trunk`` and
``crown``) stand on the grass and cars (the vehicle builder's, every part) park on the asphalt.

``World.metadata`` holds what phase 1 and the evaluation need:

- ``drive_path``: waypoints ``[x, y]`` that a ground robot of radius 0.4 m can follow: along the
  sidewalks and across the road once; in ``block`` also over the grass along the north and east
  edges and back through the south lawn, since ground 20 m away is sampled too sparsely by a
  LiDAR and too coarsely by a camera at grazing angles to map from the sidewalks alone;
- ``terrain_patches``: one entry per connected patch, ``{"class", "polygon"}`` with the
  polygon's outline ``[[x, y], ...]`` (no holes); :func:`terrain_patches` reads them back.

Scenarios: ``block`` (100 m x 60 m, 8 cars, 12 trees) and ``small`` (40 m x 30 m, 2 cars,
2 trees; a quick world for tests). The layout is fixed per scenario; the seed places the cars
(slots, heading, size) and the trees (position, size).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import GeometryCollection, Point, Polygon
from shapely.geometry.base import BaseGeometry

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.layout import Slot, add_vehicles, place_vehicles
from seminspect.worlds.shapes import Piece, cylinder, pose_matrix, sphere
from seminspect.worlds.world import World

TERRAIN_CLASSES: tuple[str, ...] = ("sidewalk", "grass", "asphalt")
TREE_PARTS: tuple[str, ...] = ("trunk", "crown")
#: Trees keep this far from the edge of their grass patch, so crowns stay over grass (metres).
TREE_MARGIN = 3.0
#: Tree trunks stand at least this far apart (metres).
TREE_SPACING = 9.0
#: Cars keep this far inside the asphalt (metres).
CAR_MARGIN = 0.3

Rect = tuple[float, float, float, float]  # x0, y0, x1, y1


@dataclass(frozen=True)
class Layout:
    """One scenario: size, terrain patches (unions of rectangles), slots and counts."""

    size: tuple[float, float, float]
    patches: tuple[tuple[str, tuple[Rect, ...]], ...]
    car_rows: tuple[tuple[float, float, float, float], ...]  # y, x_first, x_last, yaw
    bay_rows: tuple[tuple[float, float, float], ...]  # y, x_first, x_last (cars face north)
    cars: int
    trees: int
    drive_path: tuple[tuple[float, float], ...]
    keep_clear: tuple[Rect, ...]  # no car here: the road crossing and the start


_BLOCK = Layout(
    size=(100.0, 60.0, 10.0),
    patches=(
        ("grass", ((0.0, 0.0, 100.0, 21.0),)),
        ("sidewalk", ((0.0, 21.0, 100.0, 24.0),)),
        ("asphalt", ((0.0, 24.0, 100.0, 31.0),)),
        ("sidewalk", ((0.0, 31.0, 100.0, 34.0), (30.0, 34.0, 33.0, 60.0))),
        ("asphalt", ((58.0, 34.0, 88.0, 50.0),)),
        ("grass", ((0.0, 34.0, 30.0, 60.0),)),
        (
            "grass",
            ((33.0, 34.0, 58.0, 60.0), (58.0, 50.0, 88.0, 60.0), (88.0, 34.0, 100.0, 60.0)),
        ),
    ),
    car_rows=((25.8, 6.0, 90.0, 0.0), (29.2, 6.0, 90.0, math.pi)),
    bay_rows=((40.0, 62.0, 84.0),),
    cars=8,
    trees=12,
    drive_path=(
        (3.0, 36.5),
        (3.0, 57.0),
        (97.0, 57.0),
        (97.0, 32.5),
        (2.0, 32.5),
        (2.0, 22.5),
        (97.0, 22.5),
        (97.0, 8.0),
        (3.0, 8.0),
    ),
    keep_clear=((0.0, 24.0, 5.0, 31.0),),
)

_SMALL = Layout(
    size=(40.0, 30.0, 10.0),
    patches=(
        ("grass", ((0.0, 0.0, 40.0, 8.0),)),
        ("sidewalk", ((0.0, 8.0, 40.0, 11.0),)),
        ("asphalt", ((0.0, 11.0, 40.0, 18.0),)),
        ("sidewalk", ((0.0, 18.0, 40.0, 21.0),)),
        ("grass", ((0.0, 21.0, 40.0, 30.0),)),
    ),
    car_rows=((12.8, 6.0, 32.0, 0.0), (16.2, 6.0, 32.0, math.pi)),
    bay_rows=(),
    cars=2,
    trees=2,
    drive_path=((2.0, 9.5), (37.0, 9.5), (37.0, 19.5), (2.0, 19.5)),
    keep_clear=((34.0, 11.0, 40.0, 18.0),),
)

SCENARIOS: dict[str, Layout] = {"block": _BLOCK, "small": _SMALL}


def _patch_polygon(rects: Sequence[Rect]) -> Polygon:
    union = shapely.union_all([shapely.box(*r) for r in rects]).normalize()
    if not isinstance(union, Polygon) or union.interiors:
        raise InvalidInputError("an outdoor terrain patch must be one polygon without holes")
    return union


def _add_terrain(builder: WorldBuilder, layout: Layout) -> None:
    """Two upward triangles per rectangle, labelled with the patch's terrain class."""
    for class_name, rects in layout.patches:
        for x0, y0, x1, y1 in rects:
            corners = [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)]
            builder.add_faces(corners, [(0, 1, 2), (0, 2, 3)], class_name)


def _slots(layout: Layout, rng: np.random.Generator) -> list[Slot]:
    """Kerbside slots every 3 m along the road lanes, and parking bays facing north."""
    slots = []
    for y, first, last, yaw in layout.car_rows:
        for x in np.arange(first, last + 1e-9, 3.0):
            slots.append(Slot(float(x), y, yaw + float(rng.uniform(-0.03, 0.03))))
    for y, first, last in layout.bay_rows:
        for x in np.arange(first, last + 1e-9, 3.0):
            yaw = math.pi / 2 + math.pi * int(rng.integers(2))
            slots.append(Slot(float(x), y, yaw))
    return slots


def _car_exclusion(layout: Layout, asphalt: BaseGeometry) -> BaseGeometry:
    width, depth = layout.size[:2]
    outer = shapely.box(-1e3, -1e3, width + 1e3, depth + 1e3)
    blocked = outer.difference(asphalt.buffer(-CAR_MARGIN))
    start = Point(layout.drive_path[0]).buffer(4.0)
    return shapely.union_all([blocked, start, *(shapely.box(*r) for r in layout.keep_clear)])


def tree_pieces(rng: np.random.Generator) -> list[Piece]:
    """A trunk (cylinder) under a crown (a sphere stretched up to 1.25 times upwards)."""
    trunk_radius = float(rng.uniform(0.2, 0.3))
    trunk_height = float(rng.uniform(2.2, 2.8))
    crown_radius = float(rng.uniform(1.2, 1.8))
    stretch = float(rng.uniform(1.0, 1.25))
    trunk = cylinder(trunk_radius, trunk_height, "trunk", sections=12)
    crown = sphere(crown_radius, "crown", subdivisions=2)
    centre = trunk_height + crown_radius * stretch  # the crown rests on the trunk
    return [
        trunk.transformed(pose_matrix((0.0, 0.0, trunk_height / 2))),
        crown.transformed(pose_matrix((0.0, 0.0, centre), scale=(1.0, 1.0, stretch))),
    ]


def _tree_sites(
    rng: np.random.Generator, grass: Sequence[Polygon], count: int, avoid: BaseGeometry
) -> list[tuple[float, float]]:
    """Rejection-sample trunk positions inside the grass, apart from each other and ``avoid``."""
    areas = [p.buffer(-TREE_MARGIN) for p in grass]
    usable = [a for a in areas if not a.is_empty]
    weights = np.array([a.area for a in usable])
    sites: list[tuple[float, float]] = []
    for _ in range(200 * count):
        if len(sites) == count:
            break
        area = usable[int(rng.choice(len(usable), p=weights / weights.sum()))]
        x0, y0, x1, y1 = area.bounds
        candidate = Point(rng.uniform(x0, x1), rng.uniform(y0, y1))
        if not area.contains(candidate) or candidate.distance(avoid) < TREE_MARGIN:
            continue
        if all(candidate.distance(Point(s)) >= TREE_SPACING for s in sites):
            sites.append((candidate.x, candidate.y))
    if len(sites) < count:
        raise InvalidInputError(f"only {len(sites)} of {count} trees fit on the grass")
    return sites


def generate_outdoor(scenario: str, seed: int) -> World:
    """Build the outdoor world of ``SCENARIOS[scenario]``."""
    layout = SCENARIOS[scenario]
    builder = WorldBuilder("outdoor", seed)
    _add_terrain(builder, layout)
    polygons = [(cls, _patch_polygon(rects)) for cls, rects in layout.patches]
    asphalt = shapely.union_all([p for cls, p in polygons if cls == "asphalt"])
    car_rng = make_rng(seed, "worlds", "outdoor", "cars")
    placements = place_vehicles(
        car_rng,
        _slots(layout, car_rng),
        layout.cars,
        truck_share=0.0,
        obstacles=GeometryCollection(),
        keep_clear=_car_exclusion(layout, asphalt),
    )
    add_vehicles(builder, placements)
    tree_rng = make_rng(seed, "worlds", "outdoor", "trees")
    grass = [p for cls, p in polygons if cls == "grass"]
    cars = shapely.union_all([p.footprint for p in placements])
    avoid = cars.union(shapely.LineString(layout.drive_path))
    for x, y in _tree_sites(tree_rng, grass, layout.trees, avoid):
        builder.add_object(tree_pieces(tree_rng), "tree", pose_matrix((x, y, 0.0)))
    start = layout.drive_path[0]
    heading = math.atan2(layout.drive_path[1][1] - start[1], layout.drive_path[1][0] - start[0])
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), layout.size],
        start_position=(*start, 0.0),
        start_yaw=heading,
        metadata={
            "ground_z": 0.0,
            "drive_path": [list(p) for p in layout.drive_path],
            "terrain_patches": [
                {"class": cls, "polygon": [list(c) for c in polygon.exterior.coords[:-1]]}
                for cls, polygon in polygons
            ],
        },
    )


def terrain_patches(world: World) -> list[tuple[str, Polygon]]:
    """The ``(class, polygon)`` of every terrain patch in ``world.metadata``."""
    entries = world.metadata.get("terrain_patches")
    if not entries:
        raise InvalidInputError(f"world {world.name!r} has no terrain patches in its metadata")
    try:
        return [(str(e["class"]), Polygon(e["polygon"])) for e in entries]
    except (KeyError, TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"world {world.name!r} has malformed terrain patches: {exc}"
        ) from None


def drive_path(world: World) -> NDArray[np.float64]:
    """The ``(K, 2)`` waypoints of ``world.metadata["drive_path"]``."""
    path = world.metadata.get("drive_path")
    if path is None:
        raise InvalidInputError(
            f"world {world.name!r} has no drive path; map a world that has one (e.g. 'outdoor')"
        )
    try:
        waypoints = np.asarray(path, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"world {world.name!r} has a malformed drive path") from None
    if waypoints.ndim != 2 or waypoints.shape[1] != 2 or len(waypoints) < 2:
        raise InvalidInputError(f"world {world.name!r}: a drive path needs >= 2 [x, y] waypoints")
    if not np.all(np.isfinite(waypoints)):
        raise InvalidInputError(f"world {world.name!r}: the drive path holds NaN or inf")
    return waypoints
