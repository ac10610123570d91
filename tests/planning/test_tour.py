import itertools

import numpy as np
import pytest

from seminspect.core.rng import make_rng
from seminspect.planning.tour import (
    annealed_tour,
    distance_matrix,
    open_tour_length,
    reference_tour,
)


def brute_force(start, points):
    distances = distance_matrix(start, points)
    return min(open_tour_length(distances, p) for p in itertools.permutations(range(len(points))))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_annealed_tour_is_optimal_on_small_random_sets(seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(0, 5, size=(7, 3))
    tour = annealed_tour([0, 0, 0], points, make_rng(seed, "test", "tour"))
    assert sorted(tour.order.tolist()) == list(range(7))
    assert tour.length == pytest.approx(brute_force([0, 0, 0], points), rel=1e-9)


def test_grid_of_views_is_swept_row_by_row():
    u, v = np.meshgrid(np.arange(4) * 1.1, np.arange(3) * 0.66, indexing="ij")
    points = np.column_stack([np.zeros(12), u.ravel(), v.ravel()])
    tour = annealed_tour([0, -1.1, 0], points, make_rng(0, "test"))
    distances = distance_matrix([0, -1.1, 0], points)
    nearest = open_tour_length(distances, np.argsort(distances[0, 1:]))
    assert tour.length <= nearest
    assert tour.length == pytest.approx(1.1 + 3 * 0.66 + 3 * 1.1 + 2 * 0.66 + 0.0, abs=2.5)


def test_same_seed_same_tour():
    points = np.random.default_rng(5).uniform(0, 9, size=(12, 3))
    a = annealed_tour([0, 0, 0], points, make_rng(4, "tour"))
    b = annealed_tour([0, 0, 0], points, make_rng(4, "tour"))
    np.testing.assert_array_equal(a.order, b.order)


def test_one_and_two_points():
    assert annealed_tour([0, 0, 0], [[1, 0, 0]], make_rng(0, "t")).length == pytest.approx(1.0)
    two = annealed_tour([0, 0, 0], [[3, 0, 0], [1, 0, 0]], make_rng(0, "t"))
    assert two.order.tolist() == [1, 0]
    assert two.length == pytest.approx(3.0)


def test_reference_solver_agrees_with_brute_force():
    pytest.importorskip("elkai")
    points = np.random.default_rng(9).uniform(0, 5, size=(7, 3))
    tour = reference_tour([0, 0, 0], points)
    assert sorted(tour.order.tolist()) == list(range(7))
    assert tour.length == pytest.approx(brute_force([0, 0, 0], points), abs=0.01)


def test_reference_solver_keeps_its_dummy_next_to_the_start_on_large_grids():
    pytest.importorskip("elkai")
    u, v = np.meshgrid(np.arange(11) * 1.1, np.arange(7) * 0.66, indexing="ij")
    points = np.column_stack([np.zeros(u.size), u.ravel(), v.ravel()])
    reference = reference_tour([0, -2, 0], points)
    assert sorted(reference.order.tolist()) == list(range(len(points)))
    annealed = annealed_tour([0, -2, 0], points, make_rng(0, "test"))
    assert reference.length <= annealed.length + 1e-6
