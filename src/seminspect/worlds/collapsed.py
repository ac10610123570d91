"""Collapsed multi-storey buildings with windows, people and rubble (000 Sec VI-B, Table 2).

Two scenarios, as in 000 Sec VI-B: a collapsed two-storey fire station and a collapsed five-
storey industrial building, each next to a smaller intact two-storey annex; and a ``small`` one,
a single collapsed two-storey building on a smaller site, for quick checks and tests. 000 gives
no storey counts; its Table 3 lists 4 and 10 Level nodes for the two buildings (each level a
vertical step of the camera's view), so the industrial building is five storeys (17.5 m) tall,
on a site with airspace above it, where three storeys (10.5 m) hold only six levels.
Each building is one ``building`` object whose faces carry the parts ``wall``, ``roof``,
``window``, ``rubble`` and ``person``. One end of the main building has come down: its upper
storeys are gone, a floor slab leans into the gap and rubble and casualties lie within 2 m of
the walls, which leaves a ring at 3 m from the building free for a ground robot. Storeys are
3.5 m high, so each building offers at least two inspection levels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.shapes import Piece, box, pose_matrix
from seminspect.worlds.world import World

SIZE = (80.0, 56.0, 14.0)
#: Scenarios on a site of another size than ``SIZE``; the industrial site's airspace reaches
#: 4.5 m above its 17.5 m main building, room for the robot's clearance over its top level.
SITE_SIZES = {"small": (36.0, 30.0, 10.0), "industrial": (80.0, 56.0, 22.0)}
STOREY = 3.5
START = (4.0, 4.0, 0.0)
#: Rubble and people stay this close to the walls (metres).
RUBBLE_REACH = 2.0


@dataclass(frozen=True)
class _Building:
    origin: tuple[float, float]
    length: float
    width: float
    storeys: int
    collapsed: bool
    rubble: int = 0
    people: int = 0


SCENARIOS: dict[str, tuple[_Building, ...]] = {
    "fire-station": (
        _Building((12.0, 14.0), 24.0, 14.0, 2, collapsed=True, rubble=40, people=2),
        _Building((52.0, 20.0), 10.0, 8.0, 2, collapsed=False),
    ),
    "industrial": (
        _Building((12.0, 14.0), 36.0, 20.0, 5, collapsed=True, rubble=70, people=3),
        _Building((62.0, 20.0), 12.0, 10.0, 2, collapsed=False),
    ),
    "small": (_Building((12.0, 11.0), 12.0, 8.0, 2, collapsed=True, rubble=12, people=1),),
}


def _windows(
    x_range: tuple[float, float], y_range: tuple[float, float], storeys: int
) -> list[Piece]:
    """Window panels 6 cm proud of every facade, one row per storey, every 3 m."""
    (x0, x1), (y0, y1) = x_range, y_range
    panels = []
    for level in range(storeys):
        z0 = level * STOREY + 1.0
        z1 = z0 + 1.3
        for x in np.arange(x0 + 1.5, x1 - 1.4, 3.0):
            panels.append(box((x, y0 - 0.06, z0), (x + 1.2, y0, z1), "window"))
            panels.append(box((x, y1, z0), (x + 1.2, y1 + 0.06, z1), "window"))
        for y in np.arange(y0 + 1.5, y1 - 1.4, 3.0):
            panels.append(box((x0 - 0.06, y, z0), (x0, y + 1.2, z1), "window"))
            panels.append(box((x1, y, z0), (x1 + 0.06, y + 1.2, z1), "window"))
    return panels


def _person(x: float, y: float, yaw: float) -> list[Piece]:
    """A casualty lying on the ground: legs, torso and head."""
    parts = [
        box((-0.95, -0.15, 0.0), (-0.1, 0.15, 0.2), "person"),
        box((-0.1, -0.2, 0.0), (0.55, 0.2, 0.26), "person"),
        box((0.58, -0.11, 0.0), (0.8, 0.11, 0.22), "person"),
    ]
    matrix = pose_matrix((x, y, 0.0), yaw)
    return [p.transformed(matrix) for p in parts]


def _rubble(rng: np.random.Generator, count: int, x_range: tuple, y_range: tuple) -> list[Piece]:
    pieces = []
    for _ in range(count):
        size = rng.uniform(0.3, 1.1, size=3)
        centre = (rng.uniform(*x_range), rng.uniform(*y_range), 0.3 * size.max())
        block = box(-size / 2, size / 2, "rubble")
        pieces.append(block.transformed(pose_matrix(centre, euler_xyz=rng.uniform(-0.6, 0.6, 3))))
    return pieces


def _in_reach(
    rng: np.random.Generator, x_range: tuple[float, float], y_range: tuple[float, float]
) -> tuple[float, float]:
    """A random spot in the strip within RUBBLE_REACH of the collapsed end's long walls."""
    x = rng.uniform(*x_range)
    offset = rng.uniform(0.6, RUBBLE_REACH - 0.6)
    y = y_range[0] - offset if rng.integers(2) else y_range[1] + offset
    return x, float(y)


def _building_pieces(spec: _Building, rng: np.random.Generator) -> list[Piece]:
    x0, y0 = spec.origin
    x1, y1 = x0 + spec.length, y0 + spec.width
    height = spec.storeys * STOREY
    if not spec.collapsed:
        return [
            box((x0, y0, 0.0), (x1, y1, height), "wall", top="roof"),
            *_windows((x0, x1), (y0, y1), spec.storeys),
        ]
    gap = 0.35 * spec.length  # the fallen end
    xc = x1 - gap
    stub = 1.2
    rise, run = STOREY - 0.4, gap + 0.5
    slab = box((0.0, y0 + 0.2, -0.25), (math.hypot(rise, run), y1 - 0.2, 0.0), "rubble")
    pitch = math.atan2(rise, run)
    pieces = [
        box((x0, y0, 0.0), (xc, y1, height), "wall", top="roof"),
        box((xc, y0, 0.0), (x1, y1, stub), "wall", top="rubble"),
        slab.transformed(pose_matrix((xc, 0.0, STOREY), euler_xyz=(0.0, pitch, 0.0))),
        *_windows((x0, xc), (y0, y1), spec.storeys),
    ]
    reach = (xc, x1 + RUBBLE_REACH - 0.6)
    pieces += _rubble(rng, spec.rubble, reach, (y0 - RUBBLE_REACH + 0.6, y1 + RUBBLE_REACH - 0.6))
    for _ in range(spec.people):
        x, y = _in_reach(rng, (xc, x1), (y0, y1))
        pieces += _person(x, y, float(rng.uniform(-math.pi, math.pi)))
    return pieces


def generate_collapsed(scenario: str, seed: int) -> World:
    """Build the ``fire-station``, ``industrial`` or ``small`` scenario."""
    rng = make_rng(seed, "worlds", "collapsed-buildings", scenario)
    size = SITE_SIZES.get(scenario, SIZE)
    builder = WorldBuilder("collapsed-buildings", seed)
    builder.add_ground((0.0, 0.0), size[:2])
    for spec in SCENARIOS[scenario]:
        builder.add_object(_building_pieces(spec, rng), "building")
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), size],
        start_position=START,
        start_yaw=0.0,
        metadata={"ground_z": 0.0, "storey_height": STOREY},
    )
