import numpy as np
import pytest

from seminspect.geometry.polygons import (
    hull_polygon,
    polygon_centroid,
    polygon_contains,
    polygon_meets_sector,
    ring_polygon,
)

SQUARE = [[0, 0], [4, 0], [4, 2], [0, 2]]


def test_a_simple_ring_keeps_its_points_in_order() -> None:
    np.testing.assert_array_equal(ring_polygon(SQUARE), SQUARE)
    np.testing.assert_allclose(polygon_centroid(SQUARE), [2.0, 1.0])


def test_a_self_crossing_track_falls_back_to_its_convex_hull() -> None:
    bow_tie = [[0, 0], [4, 2], [4, 0], [0, 2]]
    hull = ring_polygon(bow_tie)
    assert hull is not None and len(hull) == 4
    assert {tuple(p) for p in hull} == {tuple(p) for p in SQUARE}


@pytest.mark.parametrize(
    "points", [[], [[0, 0], [1, 1]], [[0, 0], [1, 1], [2, 2]], [[1, 1], [1, 1], [1, 1], [1, 1]]]
)
def test_no_area_means_no_polygon(points) -> None:
    assert ring_polygon(points) is None


def test_repeated_points_and_a_closed_ring_are_tolerated() -> None:
    ring = [[0, 0], [0, 0], [4, 0], [4, 2], [0, 2], [0, 0]]
    np.testing.assert_array_equal(ring_polygon(ring), SQUARE)


def test_point_in_polygon_excludes_the_boundary() -> None:
    inside = polygon_contains(SQUARE, [[1, 1], [5, 1], [4, 1], [2, 0.001]])
    assert inside.tolist() == [True, False, False, True]


def test_the_hull_of_scattered_points_holds_them_all() -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(-5, 5, size=(40, 2))
    hull = hull_polygon(points)
    assert hull is not None and 3 <= len(hull) <= 40
    assert polygon_contains(hull, points * 0.999).all()
    assert hull_polygon([[0, 0], [1, 1], [2, 2]]) is None


def test_a_sector_meets_a_polygon_only_within_its_angle_and_radius() -> None:
    wall = [[-10, 2], [10, 2], [10, 3], [-10, 3]]  # a long wall 2 m north of the origin
    north, south = np.pi / 2, -np.pi / 2
    assert polygon_meets_sector(wall, (0, 0), north, np.radians(30), 5.0)
    assert not polygon_meets_sector(wall, (0, 0), south, np.radians(30), 5.0)
    assert not polygon_meets_sector(wall, (0, 0), north, np.radians(30), 1.5)  # out of reach
    assert polygon_meets_sector(wall, (0, 2.5), south, np.radians(10), 0.1)  # standing inside
