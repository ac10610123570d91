"""bench/rl_crashes.py: the nearest surface, the map check and a flown batch's crashes."""

from __future__ import annotations

import numpy as np
import pytest

from bench_scripts import bench_script
from seminspect.missions.learning.baselines import OrbitController
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.rooms import SURFACES, sample_room

pytest.importorskip("torch")
crashes = bench_script("rl_crashes")


def test_the_nearest_surface_of_an_empty_room_is_the_floor_below():
    room = sample_room(np.random.default_rng(0), 0, EnvConfig())
    point = np.array([room.size[0] / 2, 0.5, 0.3])  # 0.3 m over the floor, 0.5 m off a wall
    assert crashes.nearest_surface_offset(room, point) == pytest.approx([0.0, 0.0, -0.3], abs=1e-4)


def test_a_surface_counts_as_mapped_only_with_an_occupied_cell_beside_it():
    cells, resolution = 21, 0.1
    occupancy = np.full((cells, cells, cells), 0.5, dtype=np.float32)  # all unknown
    ahead = np.array([0.25, 0.0, 0.0])
    assert not crashes.mapped_occupied(occupancy, ahead, resolution)
    occupancy[10, 10, 10 + 3] = 1.0  # the cell 0.3 m ahead (z, y, x)
    assert crashes.mapped_occupied(occupancy, ahead, resolution)
    assert not crashes.mapped_occupied(occupancy, -ahead, resolution)  # behind: nothing


def test_a_batch_reports_each_crash_and_the_steps_flown():
    flown = crashes.fly_batch(OrbitController(), obstacles=14, batch=0, rooms=2)
    assert flown["crashes"], "the orbit meets an obstacle in these rooms"
    for crash in flown["crashes"]:
        assert crash["struck"] in SURFACES and 0 < crash["time_s"] <= 90.0
        assert crash["speed"] > 0 and 0.0 <= crash["coverage"] <= 100.0
    assert 0 <= flown["near"] <= flown["steps"] <= 2 * 900
