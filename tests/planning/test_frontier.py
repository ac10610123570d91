"""Frontier exploration on small hand-made maps: frontiers, their gain and the choice."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.frontier import FrontierPlanner, find_frontiers, unknown_area
from sim_maps import corridor_map

BAND = (0.3, 1.5)


def two_openings_map() -> VoxelMap:
    """A 30 m x 30 m explored square with unknown strips beyond its west and east edges: a
    narrow one (2 m) 8 m west of the middle and a wide one (6 m) 8 m east of it."""
    grid = VoxelMap.empty([0, 0, -0.25], [30, 30, 2.25], 0.5)
    grid.states[:] = FREE
    grid.states[:10, :, :] = OCCUPIED
    grid.states[6:10, :, :] = UNKNOWN  # x 3-5 m: 2 m deep
    grid.states[50:, :, :] = OCCUPIED
    grid.states[50:62, :, :] = UNKNOWN  # x 25-31 m: 6 m deep (to the map's edge)
    return grid


def test_frontiers_open_onto_unknown_space_not_behind_walls() -> None:
    frontiers = find_frontiers(corridor_map(), BAND, min_cells=3, height=0.7)
    assert len(frontiers) == 1
    goal = frontiers[0].goal
    assert 9.5 <= goal[0] <= 10.0  # on the boundary with the unknown east half
    assert 1.0 < goal[1] < 7.0 and goal[2] == 0.7
    assert frontiers[0].cells >= 8


def test_no_frontier_in_a_fully_known_map() -> None:
    grid = corridor_map()
    grid.states[grid.states == UNKNOWN] = FREE
    assert find_frontiers(grid, BAND, min_cells=1, height=0.7) == []
    assert FrontierPlanner().rank(grid, BAND, [5.0, 5.0, 0.7], min_cells=1) == []


def test_the_gain_is_the_unknown_area_within_the_radius() -> None:
    grid = corridor_map()  # unknown: x >= 10 m (below the wall) and y >= 8.5 m
    far_west, on_boundary = [1.0, 4.0, 0.7], [10.0, 4.0, 0.7]
    off_map = [-15.0, 4.0, 0.7]  # its window, wrapped around, would reach the unknown half
    gains = unknown_area(grid, BAND, np.array([far_west, on_boundary, off_map]), radius=3.0)
    assert gains[0] == 0.0 and gains[2] == 0.0
    # About half of a 3 m disk lies east of the boundary.
    assert gains[1] == pytest.approx(0.5 * np.pi * 3.0**2, rel=0.15)


def test_a_wider_opening_wins_over_a_nearer_narrow_one() -> None:
    grid = two_openings_map()
    start = [12.0, 15.0, 0.7]  # 7 m from the west opening, 13 m from the east one
    ranked = FrontierPlanner(gain_radius=6.0, distance_penalty=0.05).rank(
        grid, BAND, start, min_cells=3
    )
    assert len(ranked) == 2
    best, other = ranked
    assert best.frontier.goal[0] > 20 and other.frontier.goal[0] < 10
    assert best.gain_m2 > other.gain_m2 and best.distance_m > other.distance_m
    assert best.utility == pytest.approx(best.gain_m2 * np.exp(-0.05 * best.distance_m))


def test_a_steep_distance_penalty_prefers_the_nearer_frontier() -> None:
    ranked = FrontierPlanner(gain_radius=6.0, distance_penalty=1.0).rank(
        two_openings_map(), BAND, [12.0, 15.0, 0.7], min_cells=3
    )
    assert ranked[0].frontier.goal[0] < 10


def test_the_choice_is_deterministic_and_spent_goals_are_not_chosen_again() -> None:
    grid, start = two_openings_map(), [12.0, 15.0, 0.7]
    planner = FrontierPlanner(gain_radius=6.0, distance_penalty=0.05)
    first = planner.rank(grid, BAND, start, min_cells=3)
    again = FrontierPlanner(gain_radius=6.0, distance_penalty=0.05).rank(
        grid, BAND, start, min_cells=3
    )
    assert [s.frontier.goal.tolist() for s in first] == [s.frontier.goal.tolist() for s in again]
    planner.mark_spent(first[0].frontier.goal)
    remaining = planner.rank(grid, BAND, start, min_cells=3)
    assert [s.frontier.goal.tolist() for s in remaining] == [first[1].frontier.goal.tolist()]


def test_frontiers_at_the_robots_feet_are_skipped() -> None:
    grid = two_openings_map()
    near_west = [6.0, 15.0, 0.7]  # 1 m from the west frontier
    ranked = FrontierPlanner(min_distance=3.0).rank(grid, BAND, near_west, min_cells=3)
    assert all(s.distance_m >= 3.0 for s in ranked) and len(ranked) == 1


@pytest.mark.parametrize(
    "settings",
    [{"gain_radius": 0.0}, {"distance_penalty": -0.1}, {"min_distance": float("nan")}],
)
def test_impossible_settings_are_rejected(settings) -> None:
    with pytest.raises(InvalidInputError):
        FrontierPlanner(**settings)
