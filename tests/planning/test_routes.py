import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning import grid_astar, gridmap, smoothing
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.routes import LocalPlanner, warm_up
from seminspect.planning.volumetric import VolumetricPlanner


def _robot_map() -> VoxelMap:
    """40 m x 20 m x 4 m: explored near x < 15, a wall with a door, unknown beyond x = 25."""
    grid_map = VoxelMap.empty([0, 0, 0], [40, 20, 4], 0.25)
    grid_map.states[:] = FREE
    grid_map.states[40:44, :, :] = OCCUPIED  # wall at x = 10-11 m
    grid_map.states[40:44, 60:68, :8] = FREE  # a door at y = 15-17 m, 2 m high
    grid_map.states[100:, :, :] = UNKNOWN
    return grid_map


@pytest.mark.parametrize("mode", ["ground", "aerial"])
def test_route_is_simplified_and_every_segment_is_free(mode) -> None:
    grid_map = _robot_map()
    model = CostModel(0.4, unknown_cost=1.0)
    planner = LocalPlanner(model, mode=mode, band=(0.3, 1.5))
    start, goal = np.array([2.0, 2.0, 1.0]), np.array([35.0, 3.0, 1.0])
    path = planner.plan(grid_map, start, goal)
    assert len(path.waypoints) < len(path.cells) / 10
    np.testing.assert_array_equal(path.waypoints[0], start)
    np.testing.assert_array_equal(path.waypoints[-1], goal)
    band = (0.3, 1.5) if mode == "ground" else None
    grid = CostGrid.build(grid_map, model, band)
    for a, b in zip(path.waypoints[:-1], path.waypoints[1:], strict=True):
        assert grid.segment_is_free(a, b)
    # through the door, then on into unknown space
    assert np.any(np.abs(path.waypoints[:, 1] - 16.0) < 1.0)
    if mode == "ground":
        assert np.all(path.waypoints[:, 2] == 1.0)


def test_lazy_local_route_matches_the_optimal_baseline_with_weight_one() -> None:
    grid_map = _robot_map()
    model = CostModel(0.4, unknown_cost=1.0)
    start, goal = [2.0, 2.0, 1.0], [35.0, 3.0, 1.0]
    baseline = VolumetricPlanner(grid_map, model).plan(start, goal)
    exact = LocalPlanner(model, heuristic_weight=1.0).plan(grid_map, start, goal)
    weighted = LocalPlanner(model, heuristic_weight=2.0).plan(grid_map, start, goal)
    assert exact.cost == pytest.approx(baseline.cost, rel=1e-9)
    assert baseline.cost <= weighted.cost <= 2.0 * baseline.cost
    assert weighted.expansions < exact.expansions


def test_ground_robot_passes_under_an_overhang_the_band_clears() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [10, 10, 3], 0.25)
    grid_map.states[:] = FREE
    grid_map.states[16:24, :, 8:] = OCCUPIED  # a bridge deck from 2 m up, spanning the map
    low = LocalPlanner(CostModel(0.3), mode="ground", band=(0.3, 1.5))
    path = low.plan(grid_map, [1, 5, 0.5], [9, 5, 0.5])
    assert path.length == pytest.approx(8.0)
    tall = LocalPlanner(CostModel(0.3), mode="ground", band=(0.3, 2.5))
    with pytest.raises(PlanningError, match="no path"):
        tall.plan(grid_map, [1, 5, 0.5], [9, 5, 0.5])


def test_a_start_too_close_to_a_wall_escapes_within_the_tolerance() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [10, 10, 1], 0.25)
    grid_map.states[:] = FREE
    grid_map.states[20:, :20, :] = OCCUPIED
    start = [4.8, 2.0, 0.5]  # 0.2 m from the wall, robot radius 0.4 m
    path = LocalPlanner(CostModel(0.4), mode="ground", band=(0.0, 1.0)).plan(
        grid_map, start, [4.0, 9.0, 0.5]
    )
    np.testing.assert_array_equal(path.waypoints[0], start)
    strict = LocalPlanner(CostModel(0.4), mode="ground", band=(0.0, 1.0), start_tolerance=0.0)
    with pytest.raises(PlanningError, match=r"^start \(4\.80, 2\.00, 0\.50\)"):
        strict.plan(grid_map, start, [4.0, 9.0, 0.5])


def test_each_query_sees_the_current_map() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [10, 10, 1], 0.25)
    grid_map.states[:] = FREE
    planner = LocalPlanner(CostModel(0.3), mode="ground", band=(0.0, 1.0))
    first = planner.plan(grid_map, [1, 5, 0.5], [9, 5, 0.5])
    grid_map.states[18:22, 4:36, :] = OCCUPIED  # a wall appears across the straight route
    second = planner.plan(grid_map, [1, 5, 0.5], [9, 5, 0.5])
    assert first.length == pytest.approx(8.0)
    assert second.length > 9.0


def test_bad_settings_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="mode"):
        LocalPlanner(CostModel(0.3), mode="boat")
    with pytest.raises(InvalidInputError, match="heuristic_weight"):
        LocalPlanner(CostModel(0.3), heuristic_weight=0.5)


def _compiled_signatures() -> dict[str, int]:
    from numba.core.registry import CPUDispatcher

    return {
        f"{module.__name__}.{name}": len(kernel.signatures)
        for module in (grid_astar, gridmap, smoothing)
        for name, kernel in vars(module).items()
        if isinstance(kernel, CPUDispatcher)
    }


def test_the_warm_up_compiles_every_kernel_a_mission_plan_needs() -> None:
    assert warm_up() > 0
    compiled = _compiled_signatures()
    assert sum(compiled.values()) >= 3
    # plans of both modes, into unknown space and on known space only, compile nothing more
    for unknown_cost in (1.0, None):
        for mode in ("ground", "aerial"):
            planner = LocalPlanner(CostModel(0.4, unknown_cost=unknown_cost), mode=mode)
            planner.plan(_robot_map(), [2.0, 2.0, 1.0], [35.0 if unknown_cost else 20.0, 3.0, 1.0])
    assert _compiled_signatures() == compiled
