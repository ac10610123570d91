import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.spatial_hash import PointHash

coords = st.floats(-50, 50, allow_nan=False)
points = st.lists(st.tuples(coords, coords, coords), min_size=1, max_size=40)


@given(points, st.tuples(coords, coords, coords), st.floats(0.1, 4.0))
def test_matches_a_brute_force_search(stored, query, radius) -> None:
    index: PointHash[int] = PointHash(4.0)
    for i, p in enumerate(stored):
        index.add(p, i)
    distances = np.linalg.norm(np.asarray(stored) - np.asarray(query), axis=1)
    found = index.nearest_within(query, radius)
    if distances.min() > radius:
        assert found is None
    else:
        assert found is not None and found[1] == pytest.approx(distances.min())


def test_radius_larger_than_the_cell_is_refused() -> None:
    with pytest.raises(InvalidInputError):
        PointHash[int](1.0).nearest_within([0, 0, 0], 2.0)
