"""The outdoor campus of 000 Sec VI-C: 40 m x 24 m x 2 m with three to seven parked cars.

The scenarios ``small``, ``medium`` and ``large`` hold 3, 5 and 7 cars, the three campus
scenarios of 000 Table 4. Cars park nose-to-tail in two rows of four bays; the campus is too small
for seven cars with the city's 7 m gaps, so bays here are 6.5 m apart, still wide enough for a
0.4 m robot to drive a ring at 2.5 m from every car.
"""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import GeometryCollection, Point

from seminspect.core.rng import make_rng
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.layout import Slot, add_vehicles, outside_of, place_vehicles
from seminspect.worlds.vehicles import CAR_SIZE
from seminspect.worlds.world import World

SIZE = (40.0, 24.0, 2.0)
SCENARIOS = {"small": 3, "medium": 5, "large": 7}
GAP = 6.5
START = (2.0, 12.0, 0.0)


def _bays(rng: np.random.Generator) -> list[Slot]:
    """Two rows of four bays, cars pointing along y, centred in the campus."""
    pitch_x = CAR_SIZE[1] + GAP + 0.6
    pitch_y = CAR_SIZE[0] + GAP + 0.6
    xs = SIZE[0] / 2 + pitch_x * (np.arange(4) - 1.5)
    ys = SIZE[1] / 2 + pitch_y * np.array([-0.5, 0.5])
    return [
        Slot(
            float(x + rng.uniform(-0.1, 0.1)),
            float(y + rng.uniform(-0.1, 0.1)),
            math.pi / 2 + math.pi * int(rng.integers(2)),
        )
        for y in ys
        for x in xs
    ]


def generate_campus(scenario: str, seed: int) -> World:
    """Build the campus with ``SCENARIOS[scenario]`` cars."""
    rng = make_rng(seed, "worlds", "campus")
    builder = WorldBuilder("campus", seed)
    builder.add_ground((0.0, 0.0), SIZE[:2])
    keep_clear = outside_of((0.0, 0.0), SIZE[:2], 2.5).union(Point(START[:2]).buffer(3.0))
    placements = place_vehicles(
        rng,
        _bays(rng),
        max(SCENARIOS.values()),
        truck_share=0.0,
        obstacles=GeometryCollection(),
        keep_clear=keep_clear,
        gap=GAP,
    )
    add_vehicles(builder, placements[: SCENARIOS[scenario]])
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), SIZE],
        start_position=START,
        start_yaw=0.0,
        metadata={"ground_z": 0.0},
    )
