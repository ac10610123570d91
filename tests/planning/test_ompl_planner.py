import sys

import numpy as np
import pytest

from seminspect.core.errors import PlanningError, SeminspectError
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.gridmap import CostModel
from seminspect.planning.volumetric import VolumetricPlanner


def _wall_map() -> VoxelMap:
    grid_map = VoxelMap.empty([0, 0, 0], [20, 10, 4], 0.5)
    grid_map.states[:] = FREE
    grid_map.states[18:22, 0:16, :] = OCCUPIED  # a wall with a gap at y > 8 m
    return grid_map


def test_missing_extra_is_a_clear_error(monkeypatch) -> None:
    from seminspect.planning.ompl_planner import OmplPlanner

    monkeypatch.setitem(sys.modules, "ompl", None)
    with pytest.raises(SeminspectError, match=r"seminspect\[ompl\]"):
        OmplPlanner(_wall_map(), CostModel(0.4))


@pytest.mark.parametrize("band", [None, (0.3, 1.5)])
def test_rrt_connect_finds_a_free_simplified_path(band) -> None:
    pytest.importorskip("ompl")
    from seminspect.planning.ompl_planner import OmplPlanner

    grid_map = _wall_map()
    model = CostModel(0.4)
    planner = OmplPlanner(grid_map, model, band=band, seed=1)
    start, goal = np.array([2.0, 2.0, 1.0]), np.array([18.0, 2.0, 1.0])
    path = planner.plan(start, goal)
    np.testing.assert_allclose(path.waypoints[[0, -1]], [start, goal])
    for a, b in zip(path.waypoints[:-1], path.waypoints[1:], strict=True):
        assert planner.grid.segment_is_free(a, b)
    assert path.waypoints[:, 1].max() > 8.0  # through the gap
    optimal = VolumetricPlanner(grid_map, model, band=band).plan(start, goal)
    assert path.length >= 0.95 * optimal.length  # nothing beats the grid optimum by much
    assert path.expansions > 0 and path.engine == "ompl-rrtconnect"


def test_same_seed_same_path_and_goal_regions() -> None:
    pytest.importorskip("ompl")
    from seminspect.planning.ompl_planner import OmplPlanner

    grid_map = _wall_map()
    first = OmplPlanner(grid_map, CostModel(0.4), seed=7).plan([2, 2, 1], [18, 2, 1])
    OmplPlanner(grid_map, CostModel(0.4), seed=8).plan([2, 2, 1], [18, 2, 1])
    again = OmplPlanner(grid_map, CostModel(0.4), seed=7).plan([2, 2, 1], [18, 2, 1])
    np.testing.assert_array_equal(first.waypoints, again.waypoints)
    target = np.array([10.0, 4.0, 1.0])  # inside the wall
    reach = OmplPlanner(grid_map, CostModel(0.4)).plan([2, 2, 1], target, goal_radius=1.5)
    assert np.linalg.norm(reach.waypoints[-1] - target) <= 1.5


def test_sealed_goal_fails_with_a_planning_error() -> None:
    pytest.importorskip("ompl")
    from seminspect.planning.ompl_planner import OmplPlanner

    grid_map = _wall_map()
    grid_map.states[18:22, :, :] = OCCUPIED
    planner = OmplPlanner(grid_map, CostModel(0.4), time_limit=0.3)
    with pytest.raises(PlanningError, match="RRT-Connect found no path"):
        planner.plan([2, 2, 1], [18, 2, 1])
