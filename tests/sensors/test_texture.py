"""The intensity texture is stable on surfaces: ORB matches a revisit, not another view."""

import cv2
import numpy as np
import pytest

from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel, render
from seminspect.worlds import generate_world
from sim_worlds import heading


def _match_ratio(a: np.ndarray, b: np.ndarray) -> float:
    orb = cv2.ORB_create(1000)
    ka, da = orb.detectAndCompute(a, None)
    _, db = orb.detectAndCompute(b, None)
    pairs = cv2.BFMatcher(cv2.NORM_HAMMING).knnMatch(da, db, k=2)
    good = [p for p in pairs if len(p) == 2 and p[0].distance < 0.75 * p[1].distance]
    return len(good) / len(ka)


@pytest.fixture(scope="module")
def city():
    return generate_world("city", "large", seed=0)


@pytest.mark.parametrize("index", [0, 3])
def test_revisits_match_and_other_views_do_not(city, index) -> None:
    car = city.instances_of("car", "truck")[index].centroid
    camera = CameraModel()
    here = np.array([car[0] - 4.0, car[1] - 3.0, 0.7])
    image = render(city, camera, here, quat_from_yaw(heading(here, car))).intensity
    nearby = here + np.array([0.3, 0.2, 0.0])
    revisit = render(city, camera, nearby, quat_from_yaw(heading(nearby, car) + 0.05)).intensity
    there = np.array([car[0] + 4.0, car[1] + 3.0, 0.7])
    other = render(city, camera, there, quat_from_yaw(heading(there, car))).intensity
    assert _match_ratio(image, revisit) > 0.2
    assert _match_ratio(image, other) < 0.06


def test_texture_belongs_to_the_surface(city) -> None:
    """A surface point keeps its grey level when the camera moves sideways along a wall."""
    building = city.instances_of("building")[0]
    x = building.bbox_min[0] - 4.0
    y = building.centroid[1]
    camera = CameraModel()
    shift = 6  # pixels: stepping left by 6 px at 4 m moves the wall 6 px to the right
    a = render(city, camera, (x, y, 1.5), quat_from_yaw(0.0))
    b = render(city, camera, (x, y + shift * 4.0 / camera.fx, 1.5), quat_from_yaw(0.0))
    rows = slice(200, 280)
    same = a.intensity[rows, 100:500] == b.intensity[rows, 100 + shift : 500 + shift]
    assert same.mean() > 0.9
