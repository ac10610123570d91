import itertools

import numpy as np
import pytest
from sklearn.cluster import DBSCAN

from seminspect.core.errors import InvalidInputError
from seminspect.geometry import clustering
from seminspect.geometry.clustering import MIN_GRID_POINTS, dbscan_labels


def _assert_same_as_sklearn(cloud: np.ndarray, eps: float, min_samples: int) -> None:
    expected = DBSCAN(eps=eps, min_samples=min_samples).fit_predict(cloud)
    np.testing.assert_array_equal(dbscan_labels(cloud, eps, min_samples), expected)


def _blobs(rng: np.random.Generator, n: int) -> np.ndarray:
    """Dense blobs with a sparse scatter around them, like a mask's points with bled ones."""
    centres = rng.uniform(-20, 20, (int(rng.integers(1, 5)), 3))
    members = centres[rng.integers(len(centres), size=n)]
    cloud = members + rng.normal(0, rng.uniform(0.05, 0.6), (n, 3))
    scatter = rng.random(n) < 0.1
    cloud[scatter] = rng.uniform(-30, 30, (int(scatter.sum()), 3))
    return cloud


@pytest.mark.parametrize("seed", range(40))
def test_random_clouds_match_sklearn(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(MIN_GRID_POINTS, 1500))
    eps = float(rng.uniform(0.05, 1.5))
    min_samples = int(rng.integers(1, 30))
    cloud = _blobs(rng, n) if seed % 2 else rng.uniform(-3, 3, (n, 3))
    _assert_same_as_sklearn(cloud, eps, min_samples)


@pytest.mark.parametrize("eps", [0.5, 0.25, 0.3, 0.1, 0.7])
@pytest.mark.parametrize("min_samples", [1, 2, 3, 5, 7, 8])
def test_lattices_with_points_exactly_eps_apart(eps: float, min_samples: int) -> None:
    # Neighbours along an axis lie exactly eps apart (as computed), so the "<=" decides.
    steps = np.arange(6) * eps
    lattice = np.array(list(itertools.product(steps, steps[:4], steps[:3])))
    _assert_same_as_sklearn(lattice, eps, min_samples)
    _assert_same_as_sklearn(lattice + np.array([1000.25, -20.5, 3.0]), eps, min_samples)
    line = np.column_stack([np.arange(40) * eps, np.zeros(40), np.zeros(40)])
    _assert_same_as_sklearn(line, eps, min_samples)


@pytest.mark.parametrize("min_samples", [1, 2, 3, 4])
def test_pythagorean_pairs_at_exactly_eps(min_samples: int) -> None:
    # (0.3, 0.4, 0) and (0, 0.3, 0.4) are 0.5 from the origin in exact arithmetic.
    base = np.array([[0, 0, 0], [0.3, 0.4, 0], [0, 0.3, 0.4], [0.6, 0.8, 0], [0.9, 1.2, 0]])
    cloud = np.vstack([base + np.array([3.0 * k, 0, 0]) for k in range(4)])
    _assert_same_as_sklearn(cloud, 0.5, min_samples)


@pytest.mark.parametrize("seed", range(10))
def test_duplicates_and_border_points_shared_by_two_clusters(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    blob = rng.normal(0, 0.2, (30, 3))
    cloud = np.vstack([blob, blob[:10], blob + np.array([1.1, 0, 0]), [[0.55, 0, 0]] * 3])
    order = rng.permutation(len(cloud))
    _assert_same_as_sklearn(cloud[order], 0.3, int(rng.integers(2, 12)))


@pytest.mark.parametrize("n", range(1, MIN_GRID_POINTS + 2))
@pytest.mark.parametrize("min_samples", [1, 2, 5, 20])
def test_tiny_clouds(n: int, min_samples: int) -> None:
    rng = np.random.default_rng(n)
    _assert_same_as_sklearn(rng.uniform(0, 1, (n, 3)), 0.4, min_samples)
    _assert_same_as_sklearn(np.zeros((n, 3)), 0.4, min_samples)


@pytest.mark.parametrize("eps", [0.3, 0.1, 0.7])
def test_tiny_clouds_with_pairs_exactly_eps_apart(eps: float) -> None:
    line = np.column_stack([np.arange(6) * eps, np.zeros(6), np.zeros(6)]) + 100.0
    for min_samples in (1, 2, 3):
        _assert_same_as_sklearn(line, eps, min_samples)


def test_tiny_clouds_go_to_sklearn_only_near_a_tie(monkeypatch) -> None:
    calls = []
    monkeypatch.setattr(clustering, "_sklearn_labels", lambda *args: calls.append(args))
    rng = np.random.default_rng(5)
    for _ in range(50):
        dbscan_labels(rng.uniform(0, 1, (8, 3)), 0.4, 3)
    assert not calls
    dbscan_labels(np.array([[0.0, 0, 0], [0.3, 0, 0], [5, 5, 5]]), 0.3, 2)
    assert len(calls) == 1


def test_an_empty_cloud_has_no_labels() -> None:
    assert dbscan_labels(np.empty((0, 3)), 0.5, 5).shape == (0,)


def test_min_samples_equal_to_and_above_the_cloud_size() -> None:
    cloud = np.random.default_rng(7).normal(0, 0.05, (50, 3))
    assert (dbscan_labels(cloud, 1.0, 50) == 0).all()
    assert (dbscan_labels(cloud, 1.0, 51) == -1).all()


def test_a_cloud_far_wider_than_the_cell_grid() -> None:
    rng = np.random.default_rng(3)
    cloud = np.vstack([rng.normal(0, 0.1, (40, 3)), rng.normal(5e6, 0.1, (40, 3)), [[1e7] * 3]])
    _assert_same_as_sklearn(cloud, 0.5, 5)


def test_bad_input() -> None:
    with pytest.raises(InvalidInputError):
        dbscan_labels(np.zeros((20, 2)), 0.5, 5)
    with pytest.raises(InvalidInputError):
        dbscan_labels(np.full((20, 3), np.nan), 0.5, 5)
    with pytest.raises(InvalidInputError):
        dbscan_labels(np.zeros((20, 3)), 0.0, 5)
    with pytest.raises(InvalidInputError):
        dbscan_labels(np.zeros((20, 3)), 0.5, 0)
