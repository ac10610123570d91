"""The city-scale urban world of 000 Sec VI-B: 150 m x 100 m x 5 m, cars and trucks in streets.

Three rows of 18 m streets cross four columns of them, leaving six blocks of low buildings (one
block is an open plaza). Vehicles park along the street centre lines and in the plaza, keeping
the clearances of :mod:`seminspect.worlds.layout`. The scenarios ``small``, ``medium`` and
``large`` hold 5, 10 and 20 vehicles, as the three city scenarios of 000 Sec VI-B; for one seed
they are nested (the 5 vehicles of ``small`` are the first 5 of ``large``).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Point

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.layout import Slot, add_vehicles, outside_of, place_vehicles
from seminspect.worlds.shapes import box
from seminspect.worlds.world import World

SIZE = (150.0, 100.0, 5.0)
STREET = 18.0
BLOCK = (26.0, 23.0)
SCENARIOS = {"small": 5, "medium": 10, "large": 20}
MAX_VEHICLES = 20
START = (STREET / 2, STREET / 2, 0.0)


def _block_corners() -> list[tuple[float, float]]:
    xs = [STREET + i * (BLOCK[0] + STREET) for i in range(3)]
    ys = [STREET + j * (BLOCK[1] + STREET) for j in range(2)]
    return [(x, y) for y in ys for x in xs]


def _buildings(rng: np.random.Generator, corner: tuple[float, float]) -> list[tuple]:
    """One to three buildings on a block, split along x with 1.5 m alleys between them."""
    x0, y0 = corner
    lots = int(rng.integers(1, 4))
    width = BLOCK[0] / lots
    result = []
    for k in range(lots):
        lo = (x0 + k * width + 0.75 + (0.25 if k == 0 else 0.0), y0 + 1.0)
        hi = (x0 + (k + 1) * width - 0.75 - (0.25 if k == lots - 1 else 0.0), y0 + BLOCK[1] - 1.0)
        result.append((lo, hi, float(rng.uniform(3.0, SIZE[2]))))
    return result


def _street_slots(rng: np.random.Generator) -> list[Slot]:
    slots = []
    for i in range(4):  # streets running along y
        x = STREET / 2 + i * (BLOCK[0] + STREET)
        for y in np.arange(STREET / 2, SIZE[1] - STREET / 2 + 1e-9, 7.0):
            yaw = math.pi / 2 + math.pi * int(rng.integers(2)) + rng.uniform(-0.05, 0.05)
            slots.append(Slot(x + rng.uniform(-0.3, 0.3), float(y), yaw))
    for j in range(3):  # streets running along x
        y = STREET / 2 + j * (BLOCK[1] + STREET)
        for x in np.arange(STREET / 2, SIZE[0] - STREET / 2 + 1e-9, 7.0):
            yaw = math.pi * int(rng.integers(2)) + rng.uniform(-0.05, 0.05)
            slots.append(Slot(float(x), y + rng.uniform(-0.3, 0.3), yaw))
    return slots


def _plaza_slots(rng: np.random.Generator, corner: tuple[float, float]) -> list[Slot]:
    cx, cy = corner[0] + BLOCK[0] / 2, corner[1] + BLOCK[1] / 2
    return [Slot(cx + dx, cy, float(rng.uniform(-math.pi, math.pi))) for dx in (-6.0, 6.0)]


def generate_city(scenario: str, seed: int, truck_share: float = 0.3) -> World:
    """Build the city with ``SCENARIOS[scenario]`` vehicles, ``truck_share`` of them trucks."""
    if not 0.0 <= truck_share <= 1.0:
        raise InvalidInputError(f"truck_share must lie in [0, 1], got {truck_share}")
    layout_rng = make_rng(seed, "worlds", "city", "layout")
    builder = WorldBuilder("city", seed)
    builder.add_ground((0.0, 0.0), SIZE[:2])
    corners = _block_corners()
    plaza = int(layout_rng.integers(len(corners)))
    footprints = []
    for index, corner in enumerate(corners):
        if index == plaza:
            continue
        for lo, hi, height in _buildings(layout_rng, corner):
            solid = box((*lo, 0.0), (*hi, height), "wall", top="roof")
            builder.add_object([solid], "building")
            footprints.append(shapely.box(*lo, *hi))
    vehicle_rng = make_rng(seed, "worlds", "city", "vehicles")
    slots = _street_slots(vehicle_rng) + _plaza_slots(vehicle_rng, corners[plaza])
    keep_clear = outside_of((0.0, 0.0), SIZE[:2], 4.0).union(Point(START[:2]).buffer(6.0))
    placements = place_vehicles(
        vehicle_rng,
        slots,
        MAX_VEHICLES,
        truck_share=truck_share,
        obstacles=shapely.union_all(footprints),
        keep_clear=keep_clear,
    )
    add_vehicles(builder, placements[: SCENARIOS[scenario]])
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), SIZE],
        start_position=START,
        start_yaw=0.0,
        metadata={"ground_z": 0.0, "plaza_block": plaza},
    )
