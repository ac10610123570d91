import itertools
import math

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.distance import cdist

from seminspect.core.errors import InvalidInputError, PlanningError, UnknownNameError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.grid_astar import make_query
from seminspect.planning.gridmap import CostModel
from seminspect.planning.volumetric import ENGINES, RebuildingVolumetricPlanner, VolumetricPlanner


def _reference_graph(planner: VolumetricPlanner) -> nx.Graph:
    """The grid as a networkx graph with the documented edge cost, built cell by cell."""
    grid = planner.grid
    cost, res = grid.cost.astype(np.float64), grid.resolution
    graph = nx.Graph()
    dks = (0,) if grid.planar else (-1, 0, 1)
    steps = [s for s in itertools.product((-1, 0, 1), (-1, 0, 1), dks) if any(s)]
    for cell in itertools.product(*(range(n) for n in grid.shape)):
        if not np.isfinite(cost[cell]):
            continue
        graph.add_node(cell)
        for step in steps:
            other = tuple(c + s for c, s in zip(cell, step, strict=True))
            inside = all(0 <= o < n for o, n in zip(other, grid.shape, strict=True))
            if inside and np.isfinite(cost[other]):
                length = res * math.sqrt(sum(s * s for s in step))
                graph.add_edge(cell, other, weight=length * 0.5 * (cost[cell] + cost[other]))
    return graph


def _reference_cost(planner, start, goal_cells) -> float:
    """networkx Dijkstra to a sink joined to every goal cell; infinity when unreachable."""
    graph = _reference_graph(planner)
    graph.add_node("sink")
    for cell in goal_cells:
        graph.add_edge(tuple(int(c) for c in cell), "sink", weight=0.0)
    start_cell = tuple(int(c) for c in planner.grid.cell_of(start, "start"))
    try:
        return nx.dijkstra_path_length(graph, start_cell, "sink")
    except nx.NetworkXNoPath:
        return math.inf


@st.composite
def planning_cases(draw):
    planar = draw(st.booleans())
    shape = (draw(st.integers(3, 8)), draw(st.integers(3, 8)), draw(st.integers(2, 4)))
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    states = rng.choice(
        np.array([UNKNOWN, FREE, OCCUPIED], np.uint8), size=shape, p=[0.15, 0.65, 0.2]
    )
    model = CostModel(
        robot_radius=draw(st.sampled_from([0.0, 0.5])),
        risk_radius=draw(st.sampled_from([0.0, 0.6])),
        risk_weight=draw(st.sampled_from([0.0, 2.0])),
        unknown_cost=draw(st.sampled_from([None, 1.0])),
    )
    grid_map = VoxelMap(np.zeros(3), 0.5, states)
    planner = VolumetricPlanner(grid_map, model, band=(0.0, 1.0) if planar else None)
    free = np.argwhere(np.isfinite(planner.grid.cost))
    if len(free) < 2:
        return None
    a, b = free[rng.choice(len(free), 2, replace=False)]
    centre = planner.grid.centres(np.stack([a, b]), 0.25)
    radius = draw(st.sampled_from([0.0, 0.0, 0.8]))
    return planner, centre[0], centre[1], radius


@settings(max_examples=60, deadline=None)
@given(planning_cases())
def test_astar_cost_equals_networkx_dijkstra(case) -> None:
    if case is None:
        return
    planner, start, goal, radius = case
    goal_cells = make_query(planner.grid, start, goal, radius).goal_cells
    reference = _reference_cost(planner, start, goal_cells)
    if not math.isfinite(reference):
        with pytest.raises(PlanningError, match="no path"):
            planner.plan(start, goal, goal_radius=radius)
        return
    path = planner.plan(start, goal, goal_radius=radius)
    assert path.cost == pytest.approx(reference, rel=1e-9)
    # the route is a chain of neighbouring traversable cells
    assert np.abs(np.diff(path.cells, axis=0)).max(initial=0) <= 1
    assert np.isfinite(planner.grid.costs_of(path.cells)).all()


def _city_block(resolution: float = 0.5) -> VoxelMap:
    grid_map = VoxelMap.empty([0, 0, 0], [20, 12, 4], resolution)
    grid_map.states[:] = FREE
    n = round(1 / resolution)
    grid_map.states[6 * n : 9 * n, 0 : 9 * n, :] = OCCUPIED  # a building with a street north
    grid_map.states[13 * n : 15 * n, 4 * n : 12 * n, : 2 * n] = OCCUPIED  # a truck, 2 m tall
    return grid_map


def test_all_engines_find_the_same_optimal_cost() -> None:
    grid_map = _city_block()
    model = CostModel(0.4, unknown_cost=None)
    paths = {
        engine: VolumetricPlanner(grid_map, model, engine=engine).plan([1, 1, 1], [18, 2, 1])
        for engine in ENGINES
    }
    costs = [p.cost for p in paths.values()]
    np.testing.assert_allclose(costs, costs[0], rtol=1e-9)
    assert {p.engine for p in paths.values()} == set(ENGINES)
    # the heuristic pays off: A* settles fewer cells than Dijkstra
    assert paths["astar"].expansions < paths["dijkstra"].expansions
    planar = [VolumetricPlanner(grid_map, model, (0.2, 1.5), e) for e in ENGINES]
    planar_costs = [p.plan([1, 1, 1], [18, 2, 1]).cost for p in planar]
    np.testing.assert_allclose(planar_costs, planar_costs[0], rtol=1e-9)


def test_aerial_robot_flies_over_the_truck_ground_robot_drives_around() -> None:
    grid_map = _city_block()
    model = CostModel(0.4)
    aerial = VolumetricPlanner(grid_map, model).plan([11, 8, 1], [17, 8, 1])
    ground = VolumetricPlanner(grid_map, model, band=(0.2, 1.5)).plan([11, 8, 1], [17, 8, 1])
    assert aerial.waypoints[:, 2].max() > 2.0
    assert np.all(ground.waypoints[:, 2] == 1.0)
    assert ground.waypoints[:, 1].max() > 11.0 or ground.waypoints[:, 1].min() < 4.0


@pytest.mark.parametrize("radius", [0.3, 0.7, 1.1])
def test_route_cells_keep_the_robot_radius_from_every_obstacle(radius) -> None:
    grid_map = _city_block(0.25)
    planner = VolumetricPlanner(grid_map, CostModel(radius, risk_weight=0.0))
    path = planner.plan([1, 1, 1], [18, 2, 1])
    occupied = grid_map.index_to_world(np.argwhere(grid_map.states == OCCUPIED))
    clearance = cdist(grid_map.index_to_world(path.cells), occupied).min()
    assert clearance >= radius - 1e-9
    # and the inflation is not larger than asked: the route hugs the building corner
    assert clearance < radius + grid_map.resolution


def test_risk_band_pushes_the_route_away_from_walls() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [20, 8, 1], 0.25)
    grid_map.states[:] = FREE
    grid_map.states[:, :2, :] = OCCUPIED  # a long wall along y = 0.5
    start, goal = [1, 1.2, 0.5], [19, 1.2, 0.5]
    plain = VolumetricPlanner(grid_map, CostModel(0.6, risk_weight=0.0)).plan(start, goal)
    risky = VolumetricPlanner(grid_map, CostModel(0.6, 1.5, 1.0)).plan(start, goal)
    assert np.median(risky.waypoints[:, 1]) > np.median(plain.waypoints[:, 1]) + 1.0
    assert risky.length > plain.length


def test_unknown_space_is_avoided_crossed_or_refused() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [20, 10, 1], 0.5)
    grid_map.states[:] = FREE
    grid_map.states[8:12, 0:16, :] = UNKNOWN  # an unexplored block, free way round at y > 8
    start, goal = [1, 1, 0.25], [19, 1, 0.25]
    detour = VolumetricPlanner(grid_map, CostModel(0.0, unknown_cost=None)).plan(start, goal)
    cheap = VolumetricPlanner(grid_map, CostModel(0.0, unknown_cost=0.2)).plan(start, goal)
    costly = VolumetricPlanner(grid_map, CostModel(0.0, unknown_cost=20.0)).plan(start, goal)
    crossed = grid_map.states[tuple(cheap.cells.T)] == UNKNOWN
    assert crossed.any() and cheap.length < detour.length
    assert not (grid_map.states[tuple(detour.cells.T)] == UNKNOWN).any()
    assert costly.length == pytest.approx(detour.length)
    grid_map.states[8:12, :, :] = UNKNOWN
    with pytest.raises(PlanningError, match="no path"):
        VolumetricPlanner(grid_map, CostModel(0.0)).plan(start, goal)


def test_goal_radius_stops_at_the_nearest_free_cell_around_an_occupied_target() -> None:
    grid_map = _city_block()
    planner = VolumetricPlanner(grid_map, CostModel(0.4))
    target = [14.0, 8.0, 1.0]  # inside the truck
    with pytest.raises(PlanningError, match=r"goal \(14\.00, 8\.00, 1\.00\) is inside an obst"):
        planner.plan([1, 1, 1], target)
    with pytest.raises(PlanningError, match=r"no traversable cell within 0\.5 m"):
        planner.plan([1, 1, 1], target, goal_radius=0.5)
    path = planner.plan([1, 1, 1], target, goal_radius=2.0)
    assert np.linalg.norm(path.waypoints[-1] - target) <= 2.0
    # stopping anywhere in the region is never dearer than reaching one cell of it
    end = path.waypoints[-1]
    assert path.cost <= planner.plan([1, 1, 1], end).cost + 1e-9


@pytest.mark.parametrize(
    ("start", "goal", "message"),
    [
        ([-1, 1, 1], [18, 2, 1], r"^start \(-1\.00, 1\.00, 1\.00\) is outside the map"),
        ([1, 1, 1], [18, 2, 9], r"^goal \(18\.00, 2\.00, 9\.00\) is outside the map"),
        ([7, 3, 1], [18, 2, 1], r"^start \(7\.00, 3\.00, 1\.00\) is inside an obstacle"),
        ([5.8, 3, 1], [18, 2, 1], r"^start .* within the robot radius 0\.4 m"),
    ],
)
def test_bad_ends_are_named_with_their_position(start, goal, message) -> None:
    planner = VolumetricPlanner(_city_block(0.25), CostModel(0.4))
    with pytest.raises(PlanningError, match=message):
        planner.plan(start, goal)


def test_enclosed_goal_has_no_path() -> None:
    grid_map = _city_block()
    grid_map.states[30:36, 16:22, :] = OCCUPIED
    grid_map.states[31:35, 17:21, :] = FREE  # a sealed room
    with pytest.raises(PlanningError, match=r"^no path from \(1\.00, 1\.00, 1\.00\) to"):
        VolumetricPlanner(grid_map, CostModel(0.2)).plan([1, 1, 1], [16.5, 9.5, 1.0])


def test_bad_arguments_are_refused() -> None:
    grid_map = _city_block()
    with pytest.raises(UnknownNameError, match="astar"):
        VolumetricPlanner(grid_map, CostModel(0.4), engine="a-star")
    planner = VolumetricPlanner(grid_map, CostModel(0.4))
    with pytest.raises(InvalidInputError):
        planner.plan([1, 1, math.nan], [18, 2, 1])
    with pytest.raises(InvalidInputError, match="goal_radius"):
        planner.plan([1, 1, 1], [18, 2, 1], goal_radius=-1)


def test_plans_across_the_real_geb079_corridor(shared_data) -> None:
    pytest.importorskip("pyoctomap")
    from seminspect.mapping.formats.octomap import load_octomap

    grid_map = load_octomap(shared_data / "octomap" / "geb079.bt", resolution=0.16)
    planner = VolumetricPlanner(grid_map, CostModel(0.25))  # unknown space blocked
    start, goal = np.array([-5.5, -0.4, 1.0]), np.array([26.5, -0.4, 1.0])
    path = planner.plan(start, goal)
    assert (grid_map.states[tuple(path.cells.T)] == FREE).all()
    occupied = grid_map.index_to_world(np.argwhere(grid_map.states == OCCUPIED))
    assert cdist(grid_map.index_to_world(path.cells), occupied).min() >= 0.25
    straight = float(np.linalg.norm(goal - start))
    assert straight <= path.length <= 1.15 * straight


def test_a_blocked_start_escapes_within_the_tolerance() -> None:
    grid = VoxelMap.empty([0, 0, 0], [10, 4, 1], 0.5)
    grid.states[:] = FREE
    grid.states[4, :4, :] = OCCUPIED  # a wall at x = 2..2.5 m, open above y = 2 m
    planner = VolumetricPlanner(grid, CostModel(0.6, risk_weight=0.0), band=(0.0, 1.0))
    start = [2.9, 0.5, 0.5]  # 0.4 m from the wall's cell centres: inside the inflation
    with pytest.raises(PlanningError, match="start"):
        planner.plan(start, [9.0, 1.0, 0.5])
    path = planner.plan(start, [9.0, 1.0, 0.5], start_tolerance=1.0)
    np.testing.assert_allclose(path.waypoints[0], start)
    assert np.isfinite(planner.grid.costs_of(path.cells[0]))


def test_the_mission_baseline_rebuilds_a_coarse_grid_and_shortcuts_it() -> None:
    fine = VoxelMap.empty([0, 0, 0], [12, 8, 1.2], 0.3)
    fine.states[:] = FREE
    fine.states[15:18, 0:20, :] = OCCUPIED  # a wall at x = 4.5..5.4 m up to y = 6 m
    fine.states[30:, :, :] = UNKNOWN
    model = CostModel(0.4, unknown_cost=1.0)
    baseline = RebuildingVolumetricPlanner(model, band=(0.3, 1.0), resolution=0.4)
    path = baseline.plan(fine, [1.0, 1.0, 0.7], [11.0, 1.0, 0.7], goal_radius=0.5)
    reference = VolumetricPlanner(fine.coarsened(0.4), model, band=(0.3, 1.0))
    raw = reference.plan([1.0, 1.0, 0.7], [11.0, 1.0, 0.7], goal_radius=0.5)
    assert path.cost == pytest.approx(raw.cost)  # the same optimal search on the coarse map
    assert path.length <= raw.length + 1e-9 and len(path.waypoints) < len(raw.waypoints)
    assert path.waypoints[:, 1].max() > 6.0  # around the end of the wall
    for a, b in itertools.pairwise(path.waypoints):
        assert reference.grid.segment_is_free(a, b)
    assert path.planning_time > 0 and path.engine == "volumetric-rebuilt"
