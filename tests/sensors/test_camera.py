import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.params import preset
from seminspect.core.rng import make_rng
from seminspect.core.threads import rotate_rows
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel, NoiseModel, noise_preset, render
from seminspect.sensors.noise import NormalStream, make_noise
from sim_worlds import box_world, car_world

SMALL = CameraModel(width=160, height=120)


@pytest.fixture(scope="module")
def wall():
    """A wide wall 5 m ahead of the camera (x = 5 .. 6)."""
    return box_world(lower=(5.0, -20.0, 0.0), upper=(6.0, 20.0, 9.0), size=(60.0, 60.0, 10.0))


def test_intrinsics_follow_table_1() -> None:
    camera = CameraModel()
    assert camera.fx == pytest.approx(320 / math.tan(math.radians(69.4 / 2)))
    assert camera.K[0, 2] == pytest.approx(319.5) and camera.K[1, 1] == camera.fx
    assert camera.vfov_deg == pytest.approx(2 * math.degrees(math.atan(240 / camera.fx)))
    experimental = CameraModel.from_params(preset("urban-experimental"))
    assert experimental.hfov_deg == 86.0 and experimental.max_range == 30.0
    half = camera.scaled(4)
    assert (half.width, half.height, half.hfov_deg) == (160, 120, 69.4)


@pytest.mark.parametrize(
    "kwargs", [{"width": 0}, {"hfov_deg": 180.0}, {"max_range": -1.0}, {"width": 64.5}]
)
def test_impossible_cameras_are_refused(kwargs) -> None:
    with pytest.raises(InvalidInputError):
        CameraModel(**kwargs)


def test_depth_is_measured_along_the_optical_axis(wall) -> None:
    frame = render(wall, SMALL, (0.0, 0.0, 2.0), quat_from_yaw(0.0))
    hit = frame.instance > 0
    assert hit.mean() > 0.8  # the rest is ground in front of the wall
    np.testing.assert_allclose(frame.depth[hit], 5.0, atol=1e-4)
    points = frame.points(hit)
    np.testing.assert_allclose(points[:, 0], 5.0, atol=1e-4)
    # the image's left edge sees +y, its top edge sees +z
    assert points[:10, 1].mean() > 0 and frame.points()[:, 2].max() > 3.0


def test_points_of_pixel_indices_equal_the_points_of_their_mask(wall) -> None:
    frame = render(
        wall, SMALL, (0.0, 0.0, 2.0), quat_from_yaw(0.3), odometry=((0, 1, 2), quat_from_yaw(0.2))
    )
    mask = np.random.default_rng(0).random(frame.shape) < 0.3
    mask[: frame.shape[0] // 3] = True  # sky rows: pixels with no depth are dropped
    for odometry in (False, True):
        np.testing.assert_array_equal(
            frame.pixel_points(np.flatnonzero(mask), use_odometry=odometry),
            frame.points(mask, use_odometry=odometry),
        )
    assert frame.pixel_points(np.empty(0, int)).shape == (0, 3)
    with pytest.raises(InvalidInputError, match="pixel indices"):
        frame.pixel_points([frame.depth.size])


@pytest.mark.parametrize("depth_dtype", [np.float32, np.float64])
def test_points_equal_the_numpy_back_projection(wall, depth_dtype) -> None:
    frame = render(wall, SMALL, (0.0, 0.2, 2.0), quat_from_yaw(0.4))
    frame.depth = frame.depth.astype(depth_dtype)
    valid = np.isfinite(frame.depth) & (np.random.default_rng(1).random(frame.shape) < 0.5)
    flat = np.flatnonzero(valid)
    directions, cosine = frame.camera.rays
    body = directions[flat] * (frame.depth.ravel()[flat] / cosine[flat])[:, None]
    rotation = Rotation.from_quat(frame.orientation).as_matrix()
    expected = rotate_rows(body, rotation) + frame.position
    np.testing.assert_array_equal(frame.points(valid), expected)


def test_range_limit_and_pitch(wall) -> None:
    far = render(wall, CameraModel(160, 120, max_range=4.0), (0, 0, 2), quat_from_yaw(0.0))
    seen = np.isfinite(far.depth)
    assert not (far.instance > 0).any() and far.depth[seen].max() <= 4.0
    assert (far.class_id[~seen] == 0).all() and (far.face[~seen] == -1).all()
    down = Rotation.from_euler("ZY", [0.0, math.pi / 2]).as_quat()
    floor = render(wall, SMALL, (0.0, 0.0, 2.0), down)
    np.testing.assert_allclose(floor.depth, 2.0, atol=1e-4)
    assert (floor.class_id == wall.class_id("ground")).all()


def test_labels_per_pixel() -> None:
    world = car_world()
    frame = render(
        world, SMALL, (1.5, 0.0, 6.0), Rotation.from_euler("ZY", [0, math.pi / 2]).as_quat()
    )
    centre = frame.part_id[60, 80]
    assert world.part_names[centre] == "hood"
    assert world.class_names[frame.class_id[60, 80]] == "car" and frame.instance[60, 80] == 1
    assert (frame.face[frame.instance == 0] >= -1).all()
    assert np.all(world.face_part[frame.face[frame.face >= 0]] == frame.part_id[frame.face >= 0])


def test_rendering_is_deterministic_and_noise_is_seeded(wall) -> None:
    pose = ((0.0, 1.0, 1.5), quat_from_yaw(0.3))
    a, b = render(wall, SMALL, *pose), render(wall, SMALL, *pose)
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(a.intensity, b.intensity)
    noise = noise_preset("realistic")
    n1 = render(wall, SMALL, *pose, noise=noise, rng=make_rng(4, "camera"))
    n2 = render(wall, SMALL, *pose, noise=noise, rng=make_rng(4, "camera"))
    n3 = render(wall, SMALL, *pose, noise=noise, rng=make_rng(5, "camera"))
    np.testing.assert_array_equal(n1.depth, n2.depth)
    assert not np.array_equal(n1.depth, n3.depth)
    np.testing.assert_array_equal(n1.instance, a.instance)  # labels carry no noise
    with pytest.raises(InvalidInputError, match="random generator"):
        render(wall, SMALL, *pose, noise=noise)


def test_depth_noise_grows_with_range(wall) -> None:
    noise = make_noise({"depth_noise_m": 0.01, "depth_noise_per_m": 0.02})
    spreads = []
    for distance in (2.0, 4.5):
        pose = ((5.0 - distance, 0.0, 2.0), quat_from_yaw(0.0))
        clean = render(wall, SMALL, *pose)
        noisy = render(wall, SMALL, *pose, noise=noise, rng=make_rng(0, "d"))
        hit = clean.instance > 0
        error = noisy.depth[hit] - clean.depth[hit]
        spreads.append(float(np.std(error)))
        assert abs(np.mean(error)) < 0.01
        assert spreads[-1] == pytest.approx(noise.depth_sigma(distance), rel=0.1)
    assert spreads[1] > 1.5 * spreads[0]


def test_intensity_noise_only_touches_the_image(wall) -> None:
    pose = ((0.0, 0.0, 2.0), quat_from_yaw(0.0))
    clean = render(wall, SMALL, *pose)
    noisy = render(wall, SMALL, *pose, noise=make_noise({"intensity_noise": 5.0}), rng=make_rng(1))
    delta = noisy.intensity.astype(float) - clean.intensity
    assert 3.0 < delta.std() < 6.0
    np.testing.assert_array_equal(noisy.depth, clean.depth)


def test_strided_render_and_odometry_tagging(wall) -> None:
    full = render(wall, CameraModel(), (0.0, 0.0, 2.0), quat_from_yaw(0.0))
    coarse = render(wall, CameraModel(), (0.0, 0.0, 2.0), quat_from_yaw(0.0), stride=4)
    assert coarse.shape == (120, 160) and coarse.camera.hfov_deg == full.camera.hfov_deg
    assert np.isfinite(coarse.depth).mean() == pytest.approx(
        np.isfinite(full.depth).mean(), abs=0.02
    )
    tagged = render(
        wall,
        SMALL,
        (0.0, 0.0, 2.0),
        quat_from_yaw(0.0),
        odometry=((0.0, 0.5, 2.0), quat_from_yaw(0.0)),
    )
    shift = tagged.points(use_odometry=True) - tagged.points()
    np.testing.assert_allclose(shift, np.tile([0.0, 0.5, 0.0], (len(shift), 1)), atol=1e-6)
    with pytest.raises(InvalidInputError, match="mask shape"):
        tagged.points(np.ones((3, 3), bool))
    with pytest.raises(InvalidInputError):
        render(wall, SMALL, (0.0, 0.0, math.nan), quat_from_yaw(0.0))
    with pytest.raises(InvalidInputError):
        render(wall, SMALL, (0.0, 0.0, 2.0), quat_from_yaw(0.0), stride=0)


def _reference_image_noise(frame, noise, rng) -> None:
    """The image noise as two numpy draws: the oracle the compiled single pass must equal."""
    hit = np.isfinite(frame.depth)
    dtype = np.float32 if noise.image_noise_float32 else np.float64
    if noise.depth_noise_m or noise.depth_noise_per_m:
        sigma = noise.depth_noise_m + noise.depth_noise_per_m * frame.depth[hit]
        deviates = rng.standard_normal(sigma.shape, dtype=dtype).astype(np.float32)
        noisy = frame.depth[hit] + deviates * sigma
        frame.depth[hit] = np.maximum(noisy, np.float32(1e-3))
    if noise.intensity_noise:
        deviates = rng.standard_normal(frame.intensity.shape, dtype=dtype).astype(np.float64)
        jitter = noise.intensity_noise * deviates
        frame.intensity[:] = np.clip(frame.intensity + jitter, 0, 255).astype(np.uint8)


@pytest.mark.parametrize(
    "noise",
    [
        noise_preset("realistic"),
        make_noise({"depth_noise_per_m": 0.05}),
        make_noise({"intensity_noise": 40.0}),
        make_noise({"image_noise_float32": True}, base="realistic"),
    ],
)
def test_image_noise_in_one_pass_equals_the_two_draws(noise) -> None:
    pose = ((-8.0, 1.0, 1.5), quat_from_yaw(-0.1))
    expected = render(car_world(), SMALL, *pose)
    assert 0 < np.isfinite(expected.depth).mean() < 1  # both hits and sky in view
    _reference_image_noise(expected, noise, make_rng(7, "camera"))
    noisy = render(car_world(), SMALL, *pose, noise=noise, rng=make_rng(7, "camera"))
    np.testing.assert_array_equal(noisy.depth, expected.depth)
    np.testing.assert_array_equal(noisy.intensity, expected.intensity)


def test_float32_image_noise_is_an_option_with_other_numbers() -> None:
    pose = ((-8.0, 1.0, 1.5), quat_from_yaw(-0.1))
    default = noise_preset("realistic")
    single = make_noise({"image_noise_float32": True}, base="realistic")
    frames = [
        render(car_world(), SMALL, *pose, noise=model, rng=make_rng(7, "camera"))
        for model in (default, single)
    ]
    assert not default.image_noise_float32  # published runs keep the float64 draw
    assert not np.array_equal(frames[0].depth, frames[1].depth)
    assert np.array_equal(np.isfinite(frames[0].depth), np.isfinite(frames[1].depth))
    assert NoiseModel(image_noise_float32=True).is_ideal  # no noise to draw in either dtype


def test_a_frame_cast_on_two_threads_is_the_same_frame(wall) -> None:
    camera = CameraModel()  # 640 x 480: enough rays to split
    pose = ((0.0, 1.0, 1.5), quat_from_yaw(0.3))
    noise = noise_preset("realistic")
    one = render(wall, camera, *pose, noise=noise, rng=make_rng(4, "camera"))
    two = render(wall, camera, *pose, noise=noise, rng=make_rng(4, "camera"), threads=2)
    assert np.isfinite(one.depth).any()
    for name in ("depth", "instance", "class_id", "part_id", "intensity", "face"):
        np.testing.assert_array_equal(getattr(two, name), getattr(one, name))


def test_noise_drawn_ahead_gives_the_same_frames(wall) -> None:
    noise = noise_preset("realistic")
    poses = [((0.0, y, 1.5), quat_from_yaw(0.2 * y)) for y in (0.0, 1.0, 2.0)]
    rng, stream = make_rng(3, "camera"), NormalStream(make_rng(3, "camera"), threads=2)
    for pose in poses:
        drawn = render(wall, CameraModel(), *pose, noise=noise, rng=rng)
        ahead = render(wall, CameraModel(), *pose, noise=noise, rng=stream)
        np.testing.assert_array_equal(ahead.depth, drawn.depth)
        np.testing.assert_array_equal(ahead.intensity, drawn.intensity)


def test_a_frame_without_intensity_keeps_the_depth_labels_and_noise_of_one_with_it(wall) -> None:
    noise = noise_preset("realistic")
    poses = [((0.0, y, 1.5), quat_from_yaw(0.2 * y)) for y in (0.0, 1.0, 2.0)]
    shaded, unshaded = make_rng(3, "camera"), make_rng(3, "camera")
    for k, pose in enumerate(poses):
        full = render(wall, CameraModel(), *pose, noise=noise, rng=shaded)
        # every other frame without its intensity: the next frames' noise must not move
        lean = render(wall, CameraModel(), *pose, noise=noise, rng=unshaded, intensity=k != 1)
        for name in ("depth", "instance", "class_id", "part_id", "face"):
            np.testing.assert_array_equal(getattr(lean, name), getattr(full, name))
        if k == 1:
            assert lean.intensity is None
            with pytest.raises(InvalidInputError, match="without its intensity"):
                lean.grey()
        else:
            np.testing.assert_array_equal(lean.grey(), full.intensity)
