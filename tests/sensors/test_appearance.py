"""The colour image: drawn per appearance seed, nothing fixed per label, and no change to the
images and noise draws that missions use."""

from __future__ import annotations

import math

import numpy as np
import pytest

from seminspect.geometry.transforms import quat_from_yaw_pitch
from seminspect.sensors import CameraModel, render
from seminspect.sensors.appearance import Appearance, add_colour_noise
from seminspect.sensors.noise import noise_preset
from seminspect.worlds import World, open_world


@pytest.fixture(scope="module")
def world() -> World:
    return open_world("city", "small", seed=0)


@pytest.fixture(scope="module")
def view(world: World) -> tuple[np.ndarray, np.ndarray]:
    """A pose 6 m from a car, looking at it."""
    car = next(i for i in world.instances.values() if i.class_name == "car")
    position = np.array([car.centroid[0] - 6, car.centroid[1] - 3, 1.2])
    yaw = math.atan2(car.centroid[1] - position[1], car.centroid[0] - position[0])
    return position, quat_from_yaw_pitch(yaw, 0.0)


def _frame(world, view, seed: int | None, **kwargs):
    appearance = None if seed is None else Appearance.draw(world, seed)
    camera = CameraModel(width=160, height=120)
    return render(world, camera, *view, appearance=appearance, **kwargs)


def _part_pixels(world: World, frame, *words: str) -> np.ndarray:
    parts = [i for i, name in enumerate(world.part_names) if any(w in name for w in words)]
    return np.isin(frame.part_id, parts) & (frame.class_id == world.class_names.index("car"))


def test_the_colour_image_is_the_seed_s_and_only_the_seed_s(world, view) -> None:
    first, again, other = (_frame(world, view, s) for s in (3, 3, 4))
    assert first.rgb is not None and first.rgb.shape == (120, 160, 3)
    assert np.array_equal(first.rgb, again.rgb)
    assert np.abs(first.rgb.astype(int) - other.rgb.astype(int)).mean() > 10
    assert _frame(world, view, None).rgb is None


def test_colour_changes_no_other_image_nor_the_noise_draws(world, view) -> None:
    noise = noise_preset("realistic")
    plain = _frame(world, view, None, noise=noise, rng=np.random.default_rng(7))
    coloured = _frame(world, view, 5, noise=noise, rng=np.random.default_rng(7))
    for name in ("depth", "instance", "class_id", "part_id", "intensity", "face"):
        assert np.array_equal(getattr(plain, name), getattr(coloured, name)), name


def test_no_colour_belongs_to_a_label(world, view) -> None:
    """Across appearances the car's body colour spreads over the whole range, while its grey
    level (the intensity image, fixed per label) does not move."""
    frames = [_frame(world, view, seed) for seed in range(24)]
    body = _part_pixels(world, frames[0], "door", "hood", "trunk", "body")
    assert body.sum() > 100
    colours = np.array([f.rgb[body].mean(axis=0) for f in frames])
    greys = np.array([f.intensity[body].mean() for f in frames])
    assert np.ptp(greys) == 0
    assert colours.std(axis=0).min() > 20  # every channel moves
    assert np.ptp(colours, axis=0).min() > 80


def test_materials_are_read_from_part_names(world, view) -> None:
    frame = _frame(world, view, 0)
    wheels = frame.rgb[_part_pixels(world, frame, "wheel")]
    assert len(wheels) > 20 and wheels.mean() < 40  # rubber, under any light drawn
    sky = frame.face < 0
    appearance = Appearance.draw(world, 0)
    assert np.array_equal(frame.rgb[sky][0], np.uint8(appearance.sky * 255))


def test_sensor_noise_is_the_callers_stream() -> None:
    image = np.full((200, 200, 3), 128, np.uint8)
    noisy = add_colour_noise(image, np.random.default_rng(1), sigma=4.0)
    assert np.array_equal(noisy, add_colour_noise(image, np.random.default_rng(1), sigma=4.0))
    assert noisy.astype(float).std() == pytest.approx(4.0, rel=0.05)
    white = np.full((4, 4, 3), 255, np.uint8)
    assert add_colour_noise(white, np.random.default_rng(1)).max() == 255  # clipped, no wrap
