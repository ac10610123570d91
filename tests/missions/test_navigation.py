import numpy as np
import pytest

from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.missions.navigation import Navigator
from seminspect.planning.gridmap import CostModel
from seminspect.planning.local import LocalPlanner


def corridor_map() -> VoxelMap:
    """A 20 m x 10 m map: the west half explored, a wall along y = 8 m, the east half unknown."""
    grid = VoxelMap.empty([0, 0, -0.25], [20, 10, 2.25], 0.5)
    grid.states[:20, :, :] = FREE
    grid.states[:, 16, :] = OCCUPIED  # the wall, unknown beyond it
    grid.states[:, 17:, :] = UNKNOWN
    return grid


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
