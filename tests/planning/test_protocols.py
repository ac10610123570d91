"""Every grid planner keeps the contract of planning.protocols: a free route from the start to
the goal (or to within the goal radius), its length the polyline's, and a PlanningError when
the goal cannot be reached or the start is inside an obstacle."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import ArrayLike

from seminspect.core.errors import PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.grid_astar import GridPath
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.protocols import FixedMapPlanner, RoutePlanner
from seminspect.planning.routes import LocalPlanner
from seminspect.planning.volumetric import RebuildingVolumetricPlanner, VolumetricPlanner

MODEL = CostModel(0.3)
START, GOAL = np.array([1.0, 1.0, 1.0]), np.array([9.0, 1.0, 1.0])
Plan = Callable[[VoxelMap, ArrayLike, ArrayLike, float], GridPath]


def _walled_map() -> VoxelMap:
    """10 m x 10 m x 2 m, free but for a wall at x = 5 m with a gap at y = 8-10 m."""
    voxel_map = VoxelMap.empty([0, 0, 0], [10, 10, 2], 0.25)
    voxel_map.states[:] = FREE
    voxel_map.states[20:22, :32, :] = OCCUPIED
    return voxel_map


def _on_each_call(planner: RoutePlanner) -> Plan:
    return planner.plan


def _built_once(build: Callable[[VoxelMap], FixedMapPlanner]) -> Plan:
    def plan(voxel_map: VoxelMap, start: ArrayLike, goal: ArrayLike, radius: float) -> GridPath:
        return build(voxel_map).plan(start, goal, radius)

    return plan


def _ompl(voxel_map: VoxelMap) -> FixedMapPlanner:
    ompl_planner = pytest.importorskip("seminspect.planning.ompl_planner")
    pytest.importorskip("ompl")
    return ompl_planner.OmplPlanner(voxel_map, MODEL, seed=0, time_limit=2.0)


PLANNERS: dict[str, Callable[[], Plan]] = {
    "local": lambda: _on_each_call(LocalPlanner(MODEL)),
    "local-ground": lambda: _on_each_call(LocalPlanner(MODEL, mode="ground", band=(0.3, 1.5))),
    "rebuilding-volumetric": lambda: _on_each_call(
        RebuildingVolumetricPlanner(MODEL, band=None, resolution=0.25)
    ),
    "volumetric": lambda: _built_once(lambda m: VolumetricPlanner(m, MODEL)),
    "volumetric-dijkstra": lambda: _built_once(
        lambda m: VolumetricPlanner(m, MODEL, engine="dijkstra")
    ),
    "ompl": lambda: _built_once(_ompl),
}


@pytest.fixture(params=sorted(PLANNERS))
def plan(request: pytest.FixtureRequest) -> Plan:
    return PLANNERS[request.param]()


def test_the_route_is_free_and_joins_start_and_goal(plan: Plan) -> None:
    voxel_map = _walled_map()
    path = plan(voxel_map, START, GOAL, 0.0)
    np.testing.assert_allclose(path.waypoints[0], START, atol=voxel_map.resolution)
    np.testing.assert_allclose(path.waypoints[-1], GOAL, atol=voxel_map.resolution)
    grid = CostGrid.build(voxel_map, MODEL)
    for a, b in zip(path.waypoints[:-1], path.waypoints[1:], strict=True):
        assert grid.segment_is_free(a, b)
    steps = np.linalg.norm(np.diff(path.waypoints, axis=0), axis=1)
    assert path.length == pytest.approx(float(steps.sum()))
    assert path.length > 2 * np.hypot(4.0, 7.0)  # around the wall, through its gap at y >= 8 m


def test_a_goal_radius_ends_the_route_near_the_goal(plan: Plan) -> None:
    path = plan(_walled_map(), START, GOAL, 1.5)
    assert np.linalg.norm(path.waypoints[-1] - GOAL) <= 1.5 + 1e-9


def test_an_unreachable_goal_or_a_start_in_a_wall_is_a_planning_error(plan: Plan) -> None:
    closed = _walled_map()
    closed.states[20:22, :, :] = OCCUPIED
    with pytest.raises(PlanningError):
        plan(closed, START, GOAL, 0.0)
    with pytest.raises(PlanningError):
        plan(_walled_map(), [5.2, 2.0, 1.0], GOAL, 0.0)
