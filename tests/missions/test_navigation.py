from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.missions.navigation import find_frontiers


def corridor_map() -> VoxelMap:
    """A 20 m x 10 m map: the west half explored, a wall along y = 8 m, the east half unknown."""
    grid = VoxelMap.empty([0, 0, -0.25], [20, 10, 2.25], 0.5)
    grid.states[:20, :, :] = FREE
    grid.states[:, 16, :] = OCCUPIED  # the wall, unknown beyond it
    grid.states[:, 17:, :] = UNKNOWN
    return grid


def test_frontiers_open_onto_unknown_space_not_behind_walls() -> None:
    frontiers = find_frontiers(corridor_map(), (0.3, 1.5), min_cells=3, height=0.7)
    assert len(frontiers) == 1
    goal = frontiers[0].goal
    assert 9.5 <= goal[0] <= 10.0  # on the boundary with the unknown east half
    assert 1.0 < goal[1] < 7.0 and goal[2] == 0.7
    assert frontiers[0].cells >= 8


def test_no_frontier_in_a_fully_known_map() -> None:
    grid = corridor_map()
    grid.states[grid.states == UNKNOWN] = FREE
    assert find_frontiers(grid, (0.3, 1.5), min_cells=1, height=0.7) == []
