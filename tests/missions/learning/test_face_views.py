"""What counts as a face seen: the focus-area statistics, incidence and the strict rule."""

import math

import numpy as np
import pytest

from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.face_views import (
    FaceRecord,
    FaceViews,
    face_views,
    incidence_degrees,
    strict_views,
    triangle_normals,
)
from seminspect.missions.learning.rooms import TARGET_FACES


def test_incidence_is_the_angle_to_the_normal_whatever_the_winding():
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    normals = triangle_normals(vertices, np.array([[0, 1, 2], [0, 2, 1]]))
    np.testing.assert_allclose(normals, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    down = np.array([[0.0, 0.0, -1.0]] * 2)
    slanted = np.array([[math.sin(math.radians(60)), 0.0, -math.cos(math.radians(60))]] * 2)
    np.testing.assert_allclose(incidence_degrees(normals, down), [0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(incidence_degrees(normals, slanted), [60.0, 60.0])


def test_face_views_average_over_each_rooms_faces():
    key = np.array([0, 0, 3, 5])  # two rooms of 3 faces: room 0 face 0 twice, room 1 faces 0, 2
    views = face_views(key, np.array([1.0, 2.0, 4.0, 3.0]), np.array([10.0, 30.0, 0.0, 5.0]), 6)
    np.testing.assert_array_equal(views.count, [2, 0, 0, 1, 0, 1])
    np.testing.assert_array_equal(views.distance[[0, 3, 5]], [1.5, 4.0, 3.0])
    np.testing.assert_array_equal(views.incidence[[0, 3, 5]], [20.0, 0.0, 5.0])
    assert np.isnan(views.distance[1]) and np.isnan(views.incidence[1])


def test_the_strict_rule_rejects_on_band_incidence_and_pixel_count():
    # face 0 passes; 1 is outside d_ref +- band; 2 too oblique; 3 too few pixels; 4 unseen
    views = FaceViews(
        count=np.array([4, 9, 9, 3, 0]),
        distance=np.array([1.9, 2.1, 1.5, 1.5, np.nan]),
        incidence=np.array([59.0, 10.0, 61.0, 0.0, np.nan]),
    )
    seen = strict_views(views, d_ref=1.5, band=0.5, incidence_deg=60.0, min_pixels=4)
    np.testing.assert_array_equal(seen, [True, False, False, False, False])


def _views(distance, count=10, incidence=0.0):
    """One room's views: ``distance`` per face (nan: unseen)."""
    distance = np.asarray(distance, dtype=np.float64)
    seen = np.isfinite(distance)
    return FaceViews(
        np.where(seen, count, 0), distance, np.where(seen, incidence, np.nan).astype(float)
    )


def test_the_record_keeps_strict_faces_seen_and_lenient_distances():
    config = EnvConfig()
    record = FaceRecord(1, config)
    room = np.array([0])
    first = np.full(TARGET_FACES, np.nan)
    first[:3] = [1.5, 2.9, 3.1]  # strict, lenient only, neither
    record.update(room, _views(first))
    record.update(room, _views(np.full(TARGET_FACES, np.nan)))  # out of view: stays seen
    assert record.strict[0, :3].tolist() == [True, False, False]
    assert record.strict.sum() == 1
    lenient = record.best[0] <= config.inspect_range
    assert lenient[:3].tolist() == [True, True, False] and lenient.sum() == 2
    np.testing.assert_allclose(
        record.distance_scores()[0, :3], np.exp(-config.beta * np.array([0.0, 1.4, 1.6]) ** 2)
    )
    assert not record.distance_scores()[0, 3:].any()
    record.clear(room)
    assert not record.strict.any() and np.isinf(record.best).all()


def test_the_fraction_reward_pays_the_weighted_share_so_far_and_repaid_pays_alpha_each_gain():
    room, at_d_ref = np.array([0]), np.full(TARGET_FACES, 1.5)
    fraction = FaceRecord(1, EnvConfig())
    assert fraction.update(room, _views(at_d_ref))[0] == 1.0  # every face at d_ref: all of it
    assert fraction.update(room, _views(at_d_ref))[0] == 1.0  # paid again: the level so far
    far = FaceRecord(1, EnvConfig())
    assert far.update(room, _views(np.full(TARGET_FACES, 2.5)))[0] == pytest.approx(math.exp(-1))
    repaid = FaceRecord(1, EnvConfig.legacy())
    alpha = EnvConfig.legacy().alpha
    np.testing.assert_allclose(repaid.update(room, _views(at_d_ref))[0], TARGET_FACES * alpha)
