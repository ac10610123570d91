"""The geometric path for bare clouds: ground filter, objects, errors against ground truth."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.formats.pointfiles import load_point_file
from seminspect.mapping.ground import (
    GROUND,
    OBJECT,
    GroundFilterParams,
    cloud_spacing,
    filter_errors,
    label_bare_cloud,
    windows,
)

#: Three ISPRS samples of different kinds (steep city slope, city, rural with vegetation) and
#: their bounds on the total error; the mean over all 15 is in docs/terrain.md.
ISPRS_BOUNDS = {"11": 0.14, "21": 0.04, "61": 0.06}


def plane_with_boxes(seed: int = 0, spacing: float = 0.1):
    """A sloped plane (2 %) sampled on a jittered grid, with two boxes standing on it; the
    truth of each point (ground or which box)."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(0, 20, spacing), np.arange(0, 12, spacing), indexing="ij")
    ground = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    ground[:, :2] += rng.uniform(-0.02, 0.02, (len(ground), 2))
    ground[:, 2] = 0.02 * ground[:, 0] + rng.normal(0, 0.01, len(ground))
    parts, truth = [ground], [np.full(len(ground), -1)]
    for index, (low, size) in enumerate((((3, 3), (4.5, 1.8, 1.5)), ((12, 6), (2, 2, 2.5)))):
        faces = _box_surface(rng, np.array([*low, 0.0]), np.array(size), spacing)
        faces[:, 2] += 0.02 * faces[:, 0]
        keep = ~_inside(parts[0], low, size)
        parts[0], truth[0] = parts[0][keep], truth[0][keep]
        parts.append(faces)
        truth.append(np.full(len(faces), index))
    return np.vstack(parts), np.concatenate(truth)


def _inside(points, low, size) -> np.ndarray:
    return np.all((points[:, :2] > np.array(low)) & (points[:, :2] < np.add(low, size[:2])), 1)


def _box_surface(rng, low, size, spacing) -> np.ndarray:
    """Points on the top and the four sides of a box."""
    area = 2 * (size[0] + size[1]) * size[2] + size[0] * size[1]
    n = int(area / spacing**2)
    u = rng.uniform(0, 1, (n, 3))
    face = rng.choice(5, n, p=_face_weights(size))
    point = low + u * size
    point[face == 0, 2] = low[2] + size[2]
    point[face == 1, 0] = low[0]
    point[face == 2, 0] = low[0] + size[0]
    point[face == 3, 1] = low[1]
    point[face == 4, 1] = low[1] + size[1]
    return point


def _face_weights(size) -> np.ndarray:
    areas = np.array([size[0] * size[1], *[size[1] * size[2]] * 2, *[size[0] * size[2]] * 2])
    return areas / areas.sum()


def test_a_plane_with_two_boxes_gives_ground_and_two_objects() -> None:
    points, truth = plane_with_boxes()
    bare = label_bare_cloud(points)
    assert bare.spacing == pytest.approx(0.1, rel=0.25)
    errors = filter_errors(bare.is_ground, truth < 0)
    assert errors["type_1"] < 0.01 and errors["type_2"] < 0.15
    # box points taken as ground are the foot of its sides, below dh_0 (3 spacings)
    accepted = (truth >= 0) & bare.is_ground
    assert np.all(points[accepted, 2] - 0.02 * points[accepted, 0] < 0.35)
    found = bare.object_sizes(points)
    big = [size for n, size in found if n > 100]
    assert len(big) == 2
    footprints = sorted(sorted(size[:2].tolist()) for size in big)
    np.testing.assert_allclose(footprints, [[1.8, 4.5], [2.0, 2.0]], atol=0.2)
    assert np.mean(bare.labels[truth < 0] == GROUND) > 0.99
    assert np.mean(bare.labels[truth >= 0] == OBJECT) > 0.85


def test_the_same_cloud_in_another_order_or_run_gives_the_same_labels() -> None:
    points, _ = plane_with_boxes(seed=1)
    first = label_bare_cloud(points)
    again = label_bare_cloud(points.copy())
    assert np.array_equal(first.labels, again.labels)


def test_parameters_follow_the_spacing() -> None:
    coarse, _ = plane_with_boxes(spacing=0.3)
    fine, _ = plane_with_boxes(spacing=0.1)
    assert label_bare_cloud(coarse).cell > 2 * label_bare_cloud(fine).cell
    assert windows(1.0, GroundFilterParams(max_window=20)) == [3, 5, 9, 17]


def test_errors_follow_sithole_and_vosselman() -> None:
    truth = np.array([True, True, True, True, False, False])
    predicted = np.array([True, True, True, False, True, False])
    errors = filter_errors(predicted, truth)
    assert errors == {"type_1": 0.25, "type_2": 0.5, "total": 2 / 6}


def test_bad_input_is_refused_in_one_line() -> None:
    with pytest.raises(InvalidInputError, match="at least two points"):
        cloud_spacing(np.zeros((1, 3)))
    with pytest.raises(InvalidInputError, match="on top of another"):
        cloud_spacing(np.zeros((5, 3)))
    with pytest.raises(InvalidInputError, match="slope must be >= 0"):
        GroundFilterParams(slope=-1)


@pytest.mark.parametrize("sample", sorted(ISPRS_BOUNDS))
def test_isprs_samples_meet_their_error_bound(shared_data, sample) -> None:
    folder = shared_data / "isprs_filtertest_terrain"
    truth = np.load(folder / "isprs_samples_with_ground_labels.npz")
    points = load_point_file(folder / f"samp{sample}-utm.pcd").points
    np.testing.assert_array_equal(points, truth[f"samp{sample}_xyz"].astype(np.float64))
    points -= np.floor(points.min(axis=0))
    bare = label_bare_cloud(points)
    errors = filter_errors(bare.is_ground, truth[f"samp{sample}_is_ground"])
    assert errors["total"] < ISPRS_BOUNDS[sample], errors
