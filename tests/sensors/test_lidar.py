import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import Lidar
from seminspect.sensors.noise import make_noise
from sim_worlds import box_world


@pytest.fixture(scope="module")
def room():
    return box_world(lower=(5.0, -20.0, 0.0), upper=(6.0, 20.0, 9.0), size=(60.0, 60.0, 10.0))


def test_vlp16_layout() -> None:
    lidar = Lidar()
    directions, ring = lidar.rays
    assert lidar.columns == 1800 and directions.shape == (16 * 1800, 3)
    elevation = np.degrees(np.arcsin(directions[:, 2]))
    np.testing.assert_allclose(np.unique(elevation.round(3)), np.linspace(-15, 15, 16), atol=1e-3)
    assert ring.min() == 0 and ring.max() == 15
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-6)


def test_scan_points_labels_and_range(room) -> None:
    lidar = Lidar(horizontal_resolution_deg=1.0)
    scan = lidar.scan(room, (0.0, 0.0, 1.0), quat_from_yaw(0.0))
    on_wall = scan.instance > 0
    np.testing.assert_allclose(scan.points[on_wall, 0], 5.0, atol=1e-4)
    assert np.all(room.class_names[c] == "ground" for c in scan.class_id[~on_wall])
    # the wall covers the azimuths within atan(20 / 5) of +x, for every beam
    azimuth = np.degrees(np.arctan2(scan.points[on_wall, 1], scan.points[on_wall, 0]))
    assert np.abs(azimuth).max() < 76.0 and np.abs(azimuth).max() > 70.0
    short = Lidar(horizontal_resolution_deg=1.0, max_range=4.0).scan(
        room, (0, 0, 1), quat_from_yaw(0)
    )
    assert np.linalg.norm(short.points - short.origin, axis=1).max() <= 4.0
    assert not (short.instance > 0).any()


def test_orientation_turns_the_scan(room) -> None:
    lidar = Lidar(beams=4, horizontal_resolution_deg=2.0)
    level = lidar.scan(room, (0.0, 0.0, 1.0), quat_from_yaw(0.0))
    turned = lidar.scan(room, (0.0, 0.0, 1.0), quat_from_yaw(math.pi / 2))
    # a full turn of azimuth: the same points, listed from another start
    assert len(level.points) == len(turned.points)
    np.testing.assert_allclose(np.sort(level.points[:, 0]), np.sort(turned.points[:, 0]), atol=1e-3)


def test_range_noise(room) -> None:
    lidar = Lidar(horizontal_resolution_deg=1.0)
    clean = lidar.scan(room, (0, 0, 1), quat_from_yaw(0))
    noise = make_noise({"lidar_range_noise_m": 0.05})
    noisy = lidar.scan(room, (0, 0, 1), quat_from_yaw(0), noise=noise, rng=make_rng(3))
    delta = np.linalg.norm(noisy.points - noisy.origin, axis=1) - np.linalg.norm(
        clean.points - clean.origin, axis=1
    )
    assert delta.std() == pytest.approx(0.05, rel=0.1)
    np.testing.assert_array_equal(noisy.instance, clean.instance)
    with pytest.raises(InvalidInputError, match="random generator"):
        lidar.scan(room, (0, 0, 1), quat_from_yaw(0), noise=noise)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"beams": 0},
        {"min_elevation_deg": 20.0},
        {"horizontal_resolution_deg": 0.0},
        {"max_range": 0},
    ],
)
def test_impossible_lidars_are_refused(kwargs) -> None:
    with pytest.raises(InvalidInputError):
        Lidar(**kwargs)


def test_a_scan_cast_on_two_threads_is_the_same_scan(room) -> None:
    pose = ((0.0, 0.0, 1.0), quat_from_yaw(0.4))
    noise = make_noise({}, base="realistic")
    one = Lidar().scan(room, *pose, noise=noise, rng=make_rng(2, "lidar"))
    two = Lidar().scan(room, *pose, noise=noise, rng=make_rng(2, "lidar"), threads=2)
    assert len(one.points) > 1000
    for name in ("points", "instance", "class_id", "part_id", "ring", "misses"):
        np.testing.assert_array_equal(getattr(two, name), getattr(one, name))


def _reference_scan(lidar, world, position, orientation, *, noise, rng):
    """The numpy selections the compiled pass replaced: the oracle, bit for bit."""
    body, ring = lidar.rays
    rotation = Rotation.from_quat(orientation).as_matrix().astype(np.float32)
    directions = body @ rotation.T
    distance, face = world.raycaster.cast(np.asarray(position, float), directions, lidar.max_range)
    hit = face >= 0
    ranges = distance[hit].astype(np.float64)
    if noise is not None:
        ranges += rng.normal(0.0, noise.lidar_range_noise_m, ranges.shape)
        ranges = np.maximum(ranges, 0.0)
    faces = face[hit]
    return {
        "points": np.asarray(position, float) + directions[hit] * ranges[:, None],
        "instance": world.face_instance[faces],
        "class_id": world.face_class[faces],
        "part_id": world.face_part[faces],
        "ring": ring[hit],
        "misses": directions[~hit],
    }


@pytest.mark.parametrize("noisy", [False, True])
def test_returns_are_sorted_as_the_numpy_selections_did(room, noisy) -> None:
    noise = make_noise({"lidar_range_noise_m": 0.5}) if noisy else None
    for yaw, height in ((0.3, 1.0), (2.0, 0.02), (-1.2, 4.0)):
        pose = ((0.5, -1.0, height), quat_from_yaw(yaw))
        scan = Lidar().scan(room, *pose, noise=noise, rng=make_rng(4, "lidar") if noisy else None)
        expected = _reference_scan(Lidar(), room, *pose, noise=noise, rng=make_rng(4, "lidar"))
        assert 1000 < len(scan.points) < len(Lidar().rays[1])  # returns and misses both
        if noisy and height < 0.1:  # beams into the ground a few cm away: some clamped to 0
            assert np.any(np.linalg.norm(scan.points - scan.origin, axis=1) == 0.0)
        for name, values in expected.items():
            assert getattr(scan, name).dtype == values.dtype
            np.testing.assert_array_equal(getattr(scan, name), values)
