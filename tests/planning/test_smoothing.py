import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.distance import cdist

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.smoothing import (
    path_length,
    refine_path,
    remove_collinear,
    shortcut,
    voxel_segment_checker,
)
from seminspect.planning.volumetric import VolumetricPlanner


def test_path_length_of_a_polyline() -> None:
    assert path_length([[0, 0, 0], [3, 4, 0], [3, 4, 2]]) == pytest.approx(7.0)
    assert path_length([[1, 2, 3]]) == 0.0


def test_remove_collinear_keeps_shape_and_length() -> None:
    pts = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [2, 2, 0], [1, 2, 0]], float)
    out = remove_collinear(pts)
    assert out.tolist() == [[0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 2, 0]]
    assert path_length(out) == pytest.approx(path_length(pts))
    # a path that doubles back keeps its turning point
    back = np.array([[0, 0, 0], [2, 0, 0], [1, 0, 0]], float)
    assert len(remove_collinear(back)) == 3


def test_shortcut_with_a_plain_callable() -> None:
    # a wall on x = 1 for y < 1.5: only segments that stay at y >= 1.5 or x < 1 pass
    def free(a, b) -> bool:
        t = np.linspace(0, 1, 200)[:, None]
        pts = a + t * (b - a)
        return not np.any((np.abs(pts[:, 0] - 1.0) < 0.05) & (pts[:, 1] < 1.5))

    pts = np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0], [1, 2, 0], [2, 2, 0], [2, 1, 0], [2, 0, 0]])
    out = shortcut(pts.astype(float), free)
    assert out.tolist() == [[0, 0, 0], [1, 2, 0], [2, 0, 0]]  # over the top of the wall
    assert path_length(out) < path_length(pts)


def _obstacle_field(seed: int) -> VoxelMap:
    rng = np.random.default_rng(seed)
    grid_map = VoxelMap.empty([0, 0, 0], [12, 12, 3], 0.25)
    grid_map.states[:] = FREE
    for _ in range(6):
        x, y = rng.integers(4, 44, size=2)
        w, d = rng.integers(2, 10, size=2)
        grid_map.states[x : x + w, y : y + d, :] = OCCUPIED
    grid_map.states[:4, :4, :] = FREE
    grid_map.states[-4:, -4:, :] = FREE
    return grid_map


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_refinement_never_lengthens_and_keeps_clearance(seed) -> None:
    grid_map = _obstacle_field(seed)
    radius = 0.3
    planner = VolumetricPlanner(grid_map, CostModel(radius, risk_weight=0.0))
    try:
        path = planner.plan([0.4, 0.4, 1.5], [11.6, 11.6, 1.5])
    except PlanningError:  # some random fields seal the goal off
        return
    check = voxel_segment_checker(grid_map, radius)
    result = refine_path(path.waypoints, check)
    assert result.raw_length == pytest.approx(path.length)
    assert result.refined_length <= result.raw_length + 1e-9
    assert result.refined_length >= np.linalg.norm(path.waypoints[-1] - path.waypoints[0]) - 1e-9
    np.testing.assert_array_equal(result.waypoints[[0, -1]], path.waypoints[[0, -1]])
    # every new segment crosses only cells that keep the clearance: sample it densely
    occupied = grid_map.index_to_world(np.argwhere(grid_map.states == OCCUPIED))
    for a, b in zip(result.waypoints[:-1], result.waypoints[1:], strict=True):
        samples = a + np.linspace(0, 1, 400)[:, None] * (b - a)
        centres = grid_map.index_to_world(grid_map.world_to_index(samples))
        if len(occupied):
            assert cdist(centres, occupied).min() >= radius - 1e-9


def test_refinement_closes_most_of_the_gap_on_an_open_field() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [20, 20, 1], 0.5)
    grid_map.states[:] = FREE
    path = VolumetricPlanner(grid_map, CostModel(0.0)).plan([0.3, 0.3, 0.5], [19.7, 7.1, 0.5])
    refined = refine_path(path.waypoints, voxel_segment_checker(grid_map, 0.0))
    straight = float(np.linalg.norm(path.waypoints[-1] - path.waypoints[0]))
    assert path.length > straight + 0.5  # the octile route bends
    assert refined.refined_length == pytest.approx(straight)
    assert len(refined.waypoints) == 2


def test_voxel_checker_respects_clearance_and_unknown() -> None:
    grid_map = VoxelMap.empty([0, 0, 0], [10, 4, 1], 0.5)
    grid_map.states[:] = FREE
    grid_map.states[10, 0, 0] = OCCUPIED  # centre (5.25, 0.25)
    grid_map.states[4, 6, 0] = UNKNOWN  # centre (2.25, 3.25)
    a, b = np.array([0.25, 1.25, 0.25]), np.array([9.75, 1.25, 0.25])
    assert voxel_segment_checker(grid_map, 0.9)(a, b)  # passes 1.0 m from the obstacle
    assert not voxel_segment_checker(grid_map, 1.1)(a, b)
    c, d = np.array([0.25, 3.25, 0.25]), np.array([9.75, 3.25, 0.25])
    assert not voxel_segment_checker(grid_map, 0.0)(c, d)
    assert voxel_segment_checker(grid_map, 0.0, unknown_is_free=True)(c, d)
    with pytest.raises(InvalidInputError, match="clearance"):
        voxel_segment_checker(grid_map, -1.0)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_the_compiled_shortcut_on_a_grid_matches_the_generic_one(seed, lazy) -> None:
    grid_map = _obstacle_field(seed)
    grid = CostGrid.build(grid_map, CostModel(0.3, risk_weight=0.0), lazy=lazy)
    rng = np.random.default_rng(seed)
    path = rng.uniform([-1, -1, 0.2], [13, 13, 2.8], (12, 3))  # some ends lie off the map
    generic = refine_path(path, CostGrid.build(grid_map, grid.model).segment_is_free)
    compiled = refine_path(path, grid)
    np.testing.assert_array_equal(compiled.waypoints, generic.waypoints)
    assert compiled.refined_length == pytest.approx(generic.refined_length)
