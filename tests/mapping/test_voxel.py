import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap


def test_index_round_trip_and_bounds() -> None:
    grid = VoxelMap.empty([-1.0, -2.0, 0.0], [1.0, 2.0, 1.0], 0.5)
    assert grid.shape == (4, 8, 2)
    np.testing.assert_allclose(grid.upper, [1.0, 2.0, 1.0])
    centre = grid.index_to_world([1, 3, 0])
    np.testing.assert_allclose(centre, [-0.25, -0.25, 0.25])
    assert grid.world_to_index(centre).tolist() == [1, 3, 0]


def test_state_lookup_marks_outside_points() -> None:
    grid = VoxelMap.empty([0, 0, 0], [1, 1, 1], 0.5)
    grid.states[0, 0, 0] = OCCUPIED
    grid.states[1, 1, 1] = FREE
    states = grid.state_at([[0.1, 0.1, 0.1], [0.9, 0.9, 0.9], [5, 5, 5]], outside=OCCUPIED)
    assert states.tolist() == [OCCUPIED, FREE, OCCUPIED]
    assert grid.counts() == {"unknown": 6, "free": 1, "occupied": 1}
    assert UNKNOWN == 0


@pytest.mark.parametrize(
    ("lower", "upper", "res"),
    [
        ([0, 0, 0], [1, 1, 1], 0.0),
        ([0, 0, 0], [0, 1, 1], 0.1),
        ([0, 0, float("nan")], [1, 1, 1], 0.1),
    ],
)
def test_impossible_maps_are_refused(lower, upper, res) -> None:
    with pytest.raises(InvalidInputError):
        VoxelMap.empty(lower, upper, res)


def test_huge_map_is_refused_before_allocating() -> None:
    with pytest.raises(InvalidInputError, match="coarser"):
        VoxelMap.empty([0, 0, 0], [10_000, 10_000, 100], 0.01)
