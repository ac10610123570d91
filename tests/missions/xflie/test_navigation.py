import numpy as np
import pytest

from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.missions.xflie.navigation import Navigator
from seminspect.planning.gridmap import CostModel
from seminspect.planning.routes import LocalPlanner
from seminspect.sensors import LidarScan
from sim_maps import corridor_map


class _WaitingPlatform:
    """Just enough of a platform to see what the navigator charges to the clock."""

    def __init__(self) -> None:
        self.time = 0.0
        self.position = np.array([1.0, 1.0, 0.7])

    def wait(self, seconds: float) -> None:
        self.time += seconds


@pytest.mark.parametrize("charged", [False, True])
def test_planning_time_is_charged_to_the_clock_only_when_asked(charged) -> None:
    platform = _WaitingPlatform()
    navigator = Navigator(
        platform,  # type: ignore[arg-type]
        corridor_map(),
        LocalPlanner(CostModel(0.4), mode="ground", band=(0.3, 1.5)),
        on_frame=lambda frame: None,
        lidar_every_m=2.0,
        camera_every_m=4.0,
        clear_misses_to=10.0,
        charge_planning_time=charged,
    )
    navigator.planned(0.25)
    navigator.planned(0.5)
    assert navigator.stats.planning_s == pytest.approx(0.75)
    assert platform.time == pytest.approx(0.75 if charged else 0.0)


def aerial_navigator(guard_unknown: bool) -> Navigator:
    """An aerial robot at (2, 2, 2) in a map known free except an unseen block beneath x = 5 m."""
    grid = VoxelMap.empty([0, 0, 0], [10, 4, 4], 0.25)
    grid.states[:] = FREE
    grid.states[18:22, :, :7] = UNKNOWN  # x 4.5-5.5 m, up to 1.75 m: never seen
    platform = _WaitingPlatform()
    platform.position = np.array([2.0, 2.0, 2.0])
    return Navigator(
        platform,  # type: ignore[arg-type]
        grid,
        LocalPlanner(CostModel(0.6, unknown_cost=1.0), mode="aerial"),
        on_frame=lambda frame: None,
        lidar_every_m=2.0,
        camera_every_m=4.0,
        clear_misses_to=10.0,
        guard_unknown=guard_unknown,
    )


@pytest.mark.parametrize("guard_unknown", [False, True])
def test_aerial_moves_in_known_space_keep_clear_of_unseen_space_when_guarded(guard_unknown):
    navigator = aerial_navigator(guard_unknown)
    # 2.0 m high: 0.25 m above the unseen block, inside the 0.6 m clearance
    low = navigator.segment_is_free((2.0, 2.0, 2.0), (8.0, 2.0, 2.0), known_only=True)
    assert low is not guard_unknown
    navigator.platform.position = np.array([2.0, 2.0, 2.6])
    high = navigator.segment_is_free((2.0, 2.0, 2.6), (8.0, 2.0, 2.6), known_only=True)
    assert high  # 0.85 m above it
    # moves that may cross unknown space (approach legs) are not affected
    assert navigator.segment_is_free((2.0, 2.0, 1.0), (8.0, 2.0, 1.0))


def test_the_guarded_map_leaves_the_robots_own_map_unchanged() -> None:
    navigator = aerial_navigator(guard_unknown=True)
    before = navigator.occupancy.states.copy()
    guarded = navigator.guarded_map()
    assert (guarded.states[18:22, :, :7] == OCCUPIED).all()  # below the robot, at 2 m
    np.testing.assert_array_equal(navigator.occupancy.states, before)
    navigator.occupancy.states[18:22, :, 10:] = UNKNOWN  # above it: left as mapped
    assert (navigator.guarded_map().states[18:22, :, 10:] == UNKNOWN).all()


def test_space_the_robots_body_fills_is_known_free_after_a_scan() -> None:
    navigator = aerial_navigator(guard_unknown=True)
    navigator.occupancy.states[:, :, :] = UNKNOWN
    nothing = LidarScan(
        np.empty((0, 3)),
        *(np.empty(0, dtype) for dtype in (np.int32, np.int16, np.int16, np.int16)),
        origin=np.array([2.0, 2.0, 2.0]),
    )
    navigator.platform.scan = lambda: nothing  # type: ignore[attr-defined]
    navigator.sense_lidar()
    states = navigator.occupancy.states
    here = navigator.occupancy.world_to_index([2.0, 2.0, 2.0])
    assert states[tuple(here)] == FREE
    assert (states == FREE).sum() * 0.25**3 <= 4 / 3 * np.pi * 0.6**3  # only the body's ball
    assert states[tuple(navigator.occupancy.world_to_index([3.0, 2.0, 2.0]))] == UNKNOWN
