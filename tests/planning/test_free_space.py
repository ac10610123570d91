"""Free components of a cost grid, and rough ends snapped onto one of them."""

from __future__ import annotations

import numpy as np
import pytest

from seminspect.core.errors import PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.free_space import FreeSpace, snap_ends
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.map_plan import plan_on_map

RES = 0.2


def two_rooms(door: bool, small_room: bool = False) -> VoxelMap:
    """Rooms x 0..4 and 4..8 m (y 0..3, z 0..2.4) split by a wall at x = 4, with a door or
    not; ``small_room`` makes the second room 1.2 m long."""
    states = np.full((40, 15, 12), FREE, dtype=np.uint8)
    states[[0, -1], :, :] = OCCUPIED
    states[:, [0, -1], :] = OCCUPIED
    states[:, :, [0, -1]] = OCCUPIED
    states[20, :, :] = OCCUPIED
    if door:
        states[20, 5:10, 1:10] = FREE
    if small_room:
        states[27:, :, :] = OCCUPIED
    return VoxelMap(np.zeros(3), RES, states)


def space_of(voxel_map: VoxelMap, clearance: float = 0.3) -> FreeSpace:
    return FreeSpace(CostGrid.build(voxel_map, CostModel(clearance)))


def test_a_wall_splits_free_space_and_a_door_joins_it() -> None:
    assert space_of(two_rooms(door=False)).count == 2
    joined = space_of(two_rooms(door=True))
    assert joined.count == 1
    assert joined.size_of(1) == len(joined.cells)


def test_components_are_numbered_largest_first() -> None:
    space = space_of(two_rooms(door=False, small_room=True))
    assert space.count == 2
    assert space.size_of(1) > space.size_of(2)
    first = space.nearest([2.0, 1.5, 1.2])
    assert first.component == 1  # the long room


def test_an_end_inside_a_wall_is_moved_to_the_nearest_free_cell() -> None:
    space = space_of(two_rooms(door=True))
    start, goal = snap_ends(space, [0.05, 1.5, 1.2], [7.0, 1.5, 1.2])
    assert start.moved_m > 0.3  # out of the wall and its 0.3 m clearance
    assert start.moved_m < 0.7
    assert goal.moved_m < RES
    assert start.component == goal.component == 1


def test_ends_too_far_from_free_space_are_refused_with_the_distance() -> None:
    space = space_of(two_rooms(door=True))
    with pytest.raises(PlanningError, match=r"start .* is \d+\.\d+ m from the nearest free cell"):
        snap_ends(space, [-5.0, 1.5, 1.2], [7.0, 1.5, 1.2], max_move=1.0)


def test_ends_in_separate_rooms_name_both_components() -> None:
    space = space_of(two_rooms(door=False))
    with pytest.raises(PlanningError) as caught:
        snap_ends(space, [1.0, 1.5, 1.2], [7.0, 1.5, 1.2])
    message = str(caught.value)
    assert "different free components" in message
    assert message.count(" cells, ") == 2  # both sizes
    assert "comes nearest the goal at (3.70" in message  # the start room's side of the wall


def test_an_end_in_a_pocket_moves_to_the_component_both_reach() -> None:
    states = two_rooms(door=True).states.copy()
    states[30:33, 6:9, 5:8] = OCCUPIED  # a hollow block: free space inside its shell
    states[31, 7, 6] = FREE
    pocketed = VoxelMap(np.zeros(3), RES, states)
    space = space_of(pocketed, clearance=0.0)
    start, goal = snap_ends(space, [1.0, 1.5, 1.2], [6.3, 1.5, 1.3])
    assert space.nearest([6.3, 1.5, 1.3]).component != start.component  # the pocket's
    assert goal.component == start.component
    assert goal.moved_m > 0


def test_a_plan_between_rough_points_goes_through_the_door() -> None:
    plan = plan_on_map(two_rooms(door=True), [0.05, 1.5, 1.2], [7.9, 1.5, 1.2])
    door_x = plan.path.waypoints[:, 0]
    assert door_x.min() < 1.0 and door_x.max() > 7.0
    crossing = plan.path.waypoints[np.argmin(np.abs(door_x - 4.1))]
    assert 1.0 <= crossing[1] <= 2.0  # through the door's y span
    assert plan.path.length >= 7.0


def test_without_ends_the_plan_spans_the_largest_component() -> None:
    plan = plan_on_map(two_rooms(door=True))
    assert plan.chosen
    assert plan.path.length > 6.0
