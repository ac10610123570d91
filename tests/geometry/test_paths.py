import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.paths import apply_rigid, discrete_frechet, kabsch, paired_rmse


def brute_frechet(p, q):
    """The Eiter-Mannila recursion written literally."""

    @functools.cache
    def c(i, j):
        d = float(np.linalg.norm(p[i] - q[j]))
        if i == 0 and j == 0:
            return d
        if i == 0:
            return max(c(0, j - 1), d)
        if j == 0:
            return max(c(i - 1, 0), d)
        return max(min(c(i - 1, j), c(i - 1, j - 1), c(i, j - 1)), d)

    return c(len(p) - 1, len(q) - 1)


def test_parallel_lines_are_their_offset_apart():
    p = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    assert discrete_frechet(p, p + np.array([0, 1.5, 0])) == pytest.approx(1.5)


def test_extra_vertex_couples_to_the_nearest_endpoint():
    p = np.array([[0.0, 0, 0], [2, 0, 0]])
    q = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    assert discrete_frechet(p, q) == pytest.approx(1.0)


def test_reversed_path_is_far_although_the_points_are_the_same():
    p = np.array([[0.0, 0, 0], [4, 0, 0]])
    assert discrete_frechet(p, p[::-1]) == pytest.approx(4.0)


coords = st.floats(-5, 5, allow_nan=False)
paths = st.lists(st.tuples(coords, coords, coords), min_size=1, max_size=6)


@settings(max_examples=60, deadline=None)
@given(paths, paths)
def test_matches_the_literal_recursion_and_is_symmetric(p, q):
    a, b = np.array(p), np.array(q)
    expected = brute_frechet(a, b)
    assert discrete_frechet(a, b) == pytest.approx(expected)
    assert discrete_frechet(b, a) == pytest.approx(expected)


def test_frechet_rejects_nan():
    with pytest.raises(InvalidInputError):
        discrete_frechet([[0, 0, np.nan]], [[0, 0, 0]])


def test_kabsch_recovers_a_rigid_motion():
    rng = np.random.default_rng(3)
    source = rng.normal(size=(6, 3))
    rotation = Rotation.from_euler("zyx", [40, -20, 10], degrees=True).as_matrix()
    target = source @ rotation.T + [1.0, -2.0, 0.5]
    found, shift = kabsch(source, target)
    np.testing.assert_allclose(found, rotation, atol=1e-9)
    np.testing.assert_allclose(shift, [1.0, -2.0, 0.5], atol=1e-9)
    assert paired_rmse(apply_rigid(source, found, shift), target) < 1e-9


def test_kabsch_never_returns_a_reflection():
    source = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    mirrored = source * [-1, 1, 1]
    rotation, _ = kabsch(source, mirrored)
    assert np.linalg.det(rotation) == pytest.approx(1.0)


def test_kabsch_of_one_pair_is_a_translation():
    rotation, shift = kabsch([[1.0, 2, 3]], [[2.0, 2, 2]])
    np.testing.assert_allclose(rotation, np.eye(3))
    np.testing.assert_allclose(shift, [1.0, 0, -1])


def test_kabsch_lowers_rmse_and_needs_pairs():
    p = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    q = p + np.array([0.0, 0.7, 0.2])
    rotation, shift = kabsch(p, q)
    assert paired_rmse(apply_rigid(p, rotation, shift), q) < paired_rmse(p, q)
    with pytest.raises(InvalidInputError):
        kabsch(p, q[:2])
