import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.nearest import NearestIndex, median_spacing

coords = st.floats(-60, 60, allow_nan=False).map(lambda v: round(v, 1))
point = st.tuples(coords, coords, coords)


@settings(max_examples=200, deadline=None)
@given(st.lists(point, min_size=1, max_size=60), point)
def test_the_nearest_point_is_the_brute_force_one(stored, query) -> None:
    points = np.asarray(stored, dtype=float)
    found, distance = NearestIndex.build(points).nearest(query)
    distances = np.linalg.norm(points - np.asarray(query), axis=1)
    assert distance == pytest.approx(distances.min())
    assert found == int(np.flatnonzero(distances == distances.min())[0])  # ties: lowest index


def test_points_on_a_line_and_queries_far_outside() -> None:
    points = np.column_stack([np.arange(1000.0), np.zeros(1000), np.zeros(1000)])
    index = NearestIndex.build(points)
    assert index.nearest([500.2, 3.0, 0.0])[0] == 500
    assert index.nearest([-1e4, -1e4, 5.0])[0] == 0
    assert index.nearest([2e4, 0.0, 0.0]) == (999, pytest.approx(2e4 - 999))


def test_bad_points_are_refused() -> None:
    with pytest.raises(InvalidInputError):
        NearestIndex.build(np.empty((0, 3)))
    with pytest.raises(InvalidInputError):
        NearestIndex.build([[0.0, 0.0, 0.0]]).nearest([0.0, float("nan"), 0.0])


def test_median_spacing_looks_past_coincident_returns_and_samples_with_the_seed() -> None:
    xs, ys = np.meshgrid(np.arange(0, 40, 0.6), np.arange(0, 30, 0.6), indexing="ij")
    points = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    assert median_spacing(points) == pytest.approx(0.6)
    assert median_spacing(np.vstack([points, points])) == pytest.approx(0.6)
    # planar spacing ignores height: a grid lifted 1 m on a checkerboard is 0.6 m apart in x-y,
    # its nearest 3D neighbours are the diagonal ones, 0.6 * sqrt(2) m away
    board = np.round((xs + ys).ravel() / 0.6).astype(int) % 2
    lifted = points + np.column_stack([np.zeros((len(points), 2)), board])
    assert median_spacing(lifted, planar=True) == pytest.approx(0.6)
    assert median_spacing(lifted) == pytest.approx(0.6 * np.sqrt(2))
    assert np.isnan(median_spacing(points[:1])) and np.isnan(median_spacing(np.zeros((5, 3))))
    large = np.random.default_rng(0).uniform(0, 100, (50_000, 3))
    assert median_spacing(large, seed=1) == median_spacing(large, seed=1)
    assert median_spacing(large, seed=1) != median_spacing(large, seed=2)
