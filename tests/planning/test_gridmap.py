import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.distance import cdist

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.gridmap import CostGrid, CostModel, obstacle_offsets, planar_states


def _all_cells(shape):
    return np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), -1).reshape(-1, 3)


@st.composite
def maps_and_models(draw):
    shape = tuple(draw(st.integers(2, 7)) for _ in range(3))
    res = draw(st.sampled_from([0.2, 0.5, 1.0]))
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    states = rng.choice(
        np.array([UNKNOWN, FREE, OCCUPIED], np.uint8), size=shape, p=[0.2, 0.65, 0.15]
    )
    model = CostModel(
        robot_radius=draw(st.sampled_from([0.0, 0.3, 0.5, 1.0])),
        risk_radius=draw(st.sampled_from([0.0, 0.2, 0.7])),
        risk_weight=draw(st.sampled_from([0.0, 1.0, 3.0])),
        unknown_cost=draw(st.sampled_from([None, 0.0, 1.5])),
    )
    return VoxelMap(np.array([-1.0, 2.0, 0.5]), res, states), model


def _expected_costs(grid_map: VoxelMap, model: CostModel) -> np.ndarray:
    """The cost formula written out directly, with brute-force clearances."""
    cells = _all_cells(grid_map.shape)
    occupied = cells[grid_map.states.reshape(-1) == OCCUPIED]
    res = grid_map.resolution
    if len(occupied):
        dist = cdist(cells * res, occupied * res).min(axis=1)
    else:
        dist = np.full(len(cells), np.inf)
    expected = np.ones(len(cells))
    states = grid_map.states.reshape(-1)
    unknown = states == UNKNOWN
    expected[unknown] = np.inf if model.unknown_cost is None else 1 + model.unknown_cost
    if model.risk_radius > 0 and model.risk_weight > 0:
        band = dist < model.robot_radius + model.risk_radius - 1e-9
        depth = np.maximum(dist[band] - model.robot_radius, 0) / model.risk_radius
        expected[band] += model.risk_weight * (1 - depth)
    expected[(states == OCCUPIED) | (dist < model.robot_radius - 1e-9)] = np.inf
    return expected


@settings(max_examples=60, deadline=None)
@given(maps_and_models())
def test_eager_and_lazy_costs_follow_the_formula(case) -> None:
    grid_map, model = case
    eager = CostGrid.build(grid_map, model)
    lazy = CostGrid.build(grid_map, model, lazy=True)
    cells = _all_cells(grid_map.shape)
    expected = _expected_costs(grid_map, model).astype(np.float32)
    np.testing.assert_array_equal(eager.costs_of(cells), expected)
    np.testing.assert_array_equal(lazy.costs_of(cells[::-1])[::-1], expected)


def test_inflation_is_euclidean_not_a_box(free_map) -> None:
    grid_map = free_map((11, 11, 11), 0.5)
    grid_map.states[5, 5, 5] = OCCUPIED
    grid = CostGrid.build(grid_map, CostModel(robot_radius=1.2, risk_weight=0.0))
    blocked = ~np.isfinite(grid.cost)
    # 2 cells along an axis (1.0 m) is blocked, the (2, 2, 2) diagonal corner (1.73 m) is not.
    assert blocked[7, 5, 5] and blocked[5, 3, 5]
    assert not blocked[7, 7, 7]
    assert not blocked[8, 5, 5]
    assert blocked.sum() == len(obstacle_offsets(1.2, 0.5, planar=False)[0]) + 1


def test_risk_band_raises_cost_near_obstacles_only(free_map) -> None:
    grid_map = free_map((20, 3, 3), 0.5)
    grid_map.states[0, :, :] = OCCUPIED
    grid = CostGrid.build(grid_map, CostModel(robot_radius=0.5, risk_radius=1.0, risk_weight=2.0))
    along = grid.cost[:, 1, 1]
    assert np.isinf(along[0])
    # distance 0.5 m: the inner edge of the band, 1 + weight; 1.0 m: half way; 1.5 m: outside
    np.testing.assert_allclose(along[1:5], [3.0, 2.0, 1.0, 1.0])


def test_unknown_space_is_blocked_or_costed(free_map) -> None:
    grid_map = free_map((4, 4, 4))
    grid_map.states[2, 2, 2] = UNKNOWN
    blocked = CostGrid.build(grid_map, CostModel(0.0, risk_weight=0.0))
    crossable = CostGrid.build(grid_map, CostModel(0.0, risk_weight=0.0, unknown_cost=4.0))
    assert np.isinf(blocked.cost[2, 2, 2])
    assert crossable.cost[2, 2, 2] == 5.0
    # unknown cells are not obstacles: they do not inflate their neighbours
    assert blocked.cost[2, 2, 1] == 1.0


def test_planar_band_blocks_a_column_when_any_cell_in_the_band_is_occupied(free_map) -> None:
    grid_map = free_map((4, 1, 10), 0.2)  # z from 0 to 2 m
    grid_map.states[0, 0, 0] = OCCUPIED  # the floor, below the band
    grid_map.states[1, 0, 3] = OCCUPIED  # 0.6-0.8 m: inside the band
    grid_map.states[2, 0, 8] = OCCUPIED  # 1.6-1.8 m: above the band (an overhang)
    grid_map.states[3, 0, 4] = UNKNOWN
    layer = planar_states(grid_map, (0.2, 1.5))
    assert layer.shape == (4, 1, 1)
    assert layer[:, 0, 0].tolist() == [FREE, OCCUPIED, FREE, UNKNOWN]
    # a voxel overlapping the band edge counts: 1.4-1.6 m overlaps a band ending at 1.5 m
    grid_map.states[2, 0, 7] = OCCUPIED
    assert planar_states(grid_map, (0.2, 1.5))[2, 0, 0] == OCCUPIED


def test_planar_band_equals_the_whole_band_comparison(free_map) -> None:
    grid_map = free_map((30, 20, 12), 0.2)
    rng = np.random.default_rng(4)
    grid_map.states[:] = rng.choice([FREE, OCCUPIED, UNKNOWN], grid_map.shape, p=[0.8, 0.05, 0.15])
    column = grid_map.states[:, :, 2:8]  # the cells a band of 0.45-1.55 m overlaps
    occupied, unknown = (column == OCCUPIED).any(axis=2), (column == UNKNOWN).any(axis=2)
    expected = np.where(occupied, OCCUPIED, np.where(unknown, UNKNOWN, FREE))
    layer = planar_states(grid_map, (0.45, 1.55))[:, :, 0]
    assert len(np.unique(layer)) == 3
    np.testing.assert_array_equal(layer, expected)


@pytest.mark.parametrize("band", [(1.0, 0.5), (3.0, 4.0), (float("nan"), 1.0)])
def test_impossible_bands_are_refused(free_map, band) -> None:
    with pytest.raises(InvalidInputError, match="band"):
        planar_states(free_map((3, 3, 4), 0.5), band)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"robot_radius": -0.1},
        {"robot_radius": math.nan},
        {"robot_radius": 0.3, "risk_radius": math.inf},
        {"robot_radius": 0.3, "risk_weight": -1.0},
        {"robot_radius": 0.3, "unknown_cost": -2.0},
    ],
)
def test_impossible_cost_models_are_refused(kwargs) -> None:
    with pytest.raises(InvalidInputError):
        CostModel(**kwargs)


def test_points_outside_the_grid_are_named(free_map) -> None:
    grid = CostGrid.build(free_map((4, 4, 4)), CostModel(0.3))
    with pytest.raises(PlanningError, match=r"^goal \(5\.00, 1\.00, 1\.00\) is outside the map"):
        grid.cell_of([5.0, 1.0, 1.0], "goal")


def test_segment_check_sees_thin_walls_and_clear_lines(free_map) -> None:
    grid_map = free_map((10, 10, 3), 1.0)
    grid_map.states[5, 0:9, :] = OCCUPIED
    grid = CostGrid.build(grid_map, CostModel(0.0, risk_weight=0.0))
    assert not grid.segment_is_free([1.5, 1.5, 1.5], [8.5, 2.5, 1.5])
    assert grid.segment_is_free([1.5, 9.5, 1.5], [8.5, 9.5, 1.5])
    assert not grid.segment_is_free([1.5, 1.5, 1.5], [12.0, 1.5, 1.5])  # leaves the map


def test_segment_through_a_corner_steps_diagonally_like_the_grid_search(free_map) -> None:
    grid_map = free_map((3, 3, 1), 1.0)
    grid_map.states[1, 0, 0] = OCCUPIED
    grid = CostGrid.build(grid_map, CostModel(0.0, risk_weight=0.0))
    assert grid.segment_is_free([0.5, 0.5, 0.5], [1.5, 1.5, 0.5])  # a diagonal grid move
    assert grid.segment_is_free([0.5, 0.5, 0.5], [2.5, 2.5, 0.5])
    assert not grid.segment_is_free([0.5, 0.5, 0.5], [2.5, 1.5, 0.5])  # cuts through (1, 0)


@settings(max_examples=60, deadline=None)
@given(maps_and_models(), st.lists(st.floats(0.0, 0.999), min_size=6, max_size=6))
def test_a_free_segment_only_crosses_traversable_cells(case, fractions) -> None:
    grid_map, model = case
    grid = CostGrid.build(grid_map, model, lazy=True)
    size = np.asarray(grid_map.shape) * grid_map.resolution
    a = grid_map.origin + np.asarray(fractions[:3]) * size
    b = grid_map.origin + np.asarray(fractions[3:]) * size
    samples = a + np.linspace(0, 1, 2001)[:, None] * (b - a)
    cells = grid_map.world_to_index(samples)
    crossed_blocked = not np.isfinite(grid.costs_of(cells)).all()
    if grid.segment_is_free(a, b):
        assert not crossed_blocked
    if crossed_blocked:
        assert not grid.segment_is_free(a, b)
