import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.perception.localisation import erode_mask, localise_points


def test_clustering_ignores_background_that_leaked_through_the_mask() -> None:
    rng = np.random.default_rng(0)
    car = rng.normal([10.0, 0.0, 0.8], 0.3, (400, 3))
    wall = rng.normal([25.0, 0.0, 1.0], 0.3, (250, 3))  # bled pixels hitting a wall behind
    cloud = np.vstack([car, wall])
    clustered = localise_points(cloud, "cluster")
    median = localise_points(cloud, "median")
    # The per-axis median sits in the car's upper tail, about 0.26 m too far; DBSCAN does not.
    assert np.linalg.norm(clustered - [10, 0, 0.8]) < 0.05
    assert np.linalg.norm(median - [10, 0, 0.8]) > 0.15


def test_too_few_points_and_bad_methods() -> None:
    assert localise_points(np.full((3, 3), 1.0)) is None
    assert localise_points(np.array([[np.nan, 0, 0]] * 10)) is None
    with pytest.raises(InvalidInputError):
        localise_points(np.zeros((10, 3)), "mean")  # type: ignore[arg-type]


def test_erosion_shrinks_a_mask() -> None:
    mask = np.zeros((20, 20), bool)
    mask[5:15, 5:15] = True
    assert erode_mask(mask, 0).sum() == 100
    assert erode_mask(mask, 2).sum() == 36  # 6 x 6 remains
    with pytest.raises(InvalidInputError):
        erode_mask(mask, -1)
