"""Timing one query with both planners, and the scaling study's building blocks."""

import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.gridmap import CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.volumetric import VolumetricPlanner
from seminspect.studies.xflie.comparison import (
    fine_segment_validity,
    segment_validity,
    time_hierarchical,
    time_volumetric,
)
from seminspect.studies.xflie.scaling import box_city, growth_exponent, scaling_point
from sim_worlds import box_world


def test_segments_are_checked_against_the_world_at_the_robot_radius() -> None:
    world = box_world()  # a crate over x 4..6, y -1..1
    path = [[0, 0, 0.7], [0, 3, 0.7], [9, 3, 0.7], [0, 0, 0.7]]
    assert segment_validity(world, path, 0.4).tolist() == [True, True, False]
    assert not segment_validity(world, path, 2.5)[1]  # 2 m from the crate: too close for 2.5
    assert segment_validity(world, np.empty((0, 3)), 0.4).size == 0


def test_hierarchical_timing_takes_medians_of_its_repeats() -> None:
    graph = synthetic_graph(3, poses_per_level=6)
    planner = HierarchicalPlanner(graph)
    goal = graph.targets()[2].levels[0].poses[3].id
    plan, timing = time_hierarchical(lambda: planner.plan(goal, [0.0, 0.0, 0.7]), 9)
    assert plan.node_path[-1] == goal and timing.repeats == 9
    assert 0 < timing.search_s <= timing.plan_s <= timing.query_s
    assert timing.search_s >= max(timing.target_layer_s, timing.local_layers_s)
    with pytest.raises(InvalidInputError, match="repeats"):
        time_hierarchical(lambda: plan, 0)


def _walled_map() -> VoxelMap:
    grid = VoxelMap.empty([0, 0, -0.25], [12, 6, 1.75], 0.5)
    grid.states[:] = FREE
    grid.states[:, :, 0] = OCCUPIED  # the ground
    grid.states[10:12, :8, :] = OCCUPIED  # a wall at x = 5..6 m, open above y = 4 m
    return grid


def test_volumetric_timing_moves_blocked_ends_to_the_nearest_free_cell() -> None:
    planner = VolumetricPlanner(_walled_map(), CostModel(0.4), band=(0.3, 1.5))
    exact = time_volumetric(planner, [1.0, 1.0, 0.7], [11.0, 1.0, 0.7], repeats=3)
    assert exact.error is None and exact.goal_radius == 0.0
    np.testing.assert_allclose(exact.waypoints[-1], [11.0, 1.0, 0.7])
    assert exact.length > 12 and exact.waypoints[:, 1].max() > 4.4  # round the wall's end
    # start and goal in the wall's cells (a coarse grid's cells reach beyond the surfaces)
    near = time_volumetric(planner, [5.9, 1.0, 0.7], [5.2, 1.0, 0.7], repeats=1)
    assert near.error is None and near.goal_radius == pytest.approx(1.0)
    assert near.waypoints[1, 0] > 6.0 and near.waypoints[-1, 0] < 5.0  # round the wall
    outside = time_volumetric(planner, [1.0, 1.0, 0.7], [40.0, 1.0, 0.7], repeats=1)
    assert "outside the map" in outside.error and math.isnan(outside.time_s)


def test_the_box_city_has_a_box_where_the_synthetic_graph_has_a_vehicle() -> None:
    graph = synthetic_graph(6, seed=4)
    city = box_city(6, seed=4, resolution=0.5)
    for target in graph.targets():
        ring = np.array([p.position for p in target.levels[0].poses])
        centre = ring.mean(axis=0)
        assert city.state_at([[centre[0], centre[1], 0.7]])[0] == OCCUPIED
        assert np.all(city.state_at(ring) == FREE)  # its view poses stand in free space
    assert city.counts()["unknown"] == 0


def test_a_scaling_point_times_both_planners_on_the_same_queries() -> None:
    point = scaling_point(6, queries=4, repeats=3)
    assert point.targets == 6 and point.queries == 4 and point.vp_failures == 0
    assert point.graph_nodes == synthetic_graph(6).population().unified.nodes
    assert 0 < point.hp_search_s <= point.hp_plan_s and point.vp_s > 0
    assert point.ratio_search >= point.ratio_plan > 0
    assert point.map_volume_m3 > 0 and point.map_cells > 0


def test_growth_exponent_recovers_a_power_law() -> None:
    sizes = [20, 200, 2000]
    assert growth_exponent(sizes, [3e-6 * n**0.5 for n in sizes]) == pytest.approx(0.5)
    assert growth_exponent(sizes, [1e-6 * n for n in sizes]) == pytest.approx(1.0)
    with pytest.raises(InvalidInputError):
        growth_exponent([20], [1.0])
    with pytest.raises(InvalidInputError):
        growth_exponent([20, 200], [1.0, float("nan")])


def test_the_fine_check_sees_what_a_flying_body_would_touch() -> None:
    world = box_world()  # a crate over x 4..6, y -1..1, 2 m tall, on the ground
    over = [[3.0, 0.0, 2.6], [7.0, 0.0, 2.6]]  # 0.6 m over the lid
    low = [[-8.0, 3.0, 0.35], [-4.0, 3.0, 0.35]]  # 0.35 m over open ground
    assert fine_segment_validity(world, over, 0.4).tolist() == [True]
    assert fine_segment_validity(world, low, 0.4).tolist() == [False]
    assert fine_segment_validity(world, np.add(low, [0, 0, 0.2]), 0.4).tolist() == [True]
    through = [[2.0, 0.0, 1.0], [8.0, 0.0, 1.0], [8.0, 4.0, 1.0]]  # across the crate, then clear
    assert fine_segment_validity(world, through, 0.4).tolist() == [False, True]
    # The coarse aerial grid cannot tell: it turns down the clear segment low over the ground.
    assert not segment_validity(world, np.add(low, [0, 0, 0.2]), 0.4, "aerial").all()


@pytest.mark.parametrize(
    ("waypoints", "radius", "resolution", "message"),
    [
        ([[0, 0, 1], [1, 0, float("nan")]], 0.4, 0.05, "waypoints"),
        ([[0, 0, 1], [1, 0, 1]], -0.4, 0.05, "radius"),
        ([[0, 0, 1], [1, 0, 1]], 0.4, 0.0, "resolution"),
    ],
)
def test_the_fine_check_refuses_impossible_input(waypoints, radius, resolution, message) -> None:
    with pytest.raises(InvalidInputError, match=message):
        fine_segment_validity(box_world(), waypoints, radius, resolution)
