import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.depth_normals import depth_normals, incidence_cosines, viewpoint_utility

FOCAL = 50.0


def plane_depth(normal, offset, shape=(41, 61)):
    """z-depth of the plane ``normal . P = offset`` seen by a centred pinhole camera."""
    h, w = shape
    v, u = np.mgrid[0:h, 0:w].astype(float)
    rays = np.stack([(u - (w - 1) / 2) / FOCAL, (v - (h - 1) / 2) / FOCAL, np.ones_like(u)], -1)
    return offset / (rays @ np.asarray(normal, dtype=float))


def test_fronto_parallel_wall_has_the_ray_angle_as_incidence():
    depth = plane_depth([0, 0, 1], 2.0)
    h, w = depth.shape
    v, u = np.mgrid[0:h, 0:w].astype(float)
    rays = np.stack([(u - (w - 1) / 2) / FOCAL, (v - (h - 1) / 2) / FOCAL, np.ones_like(u)], -1)
    expected = 1.0 / np.linalg.norm(rays, axis=-1)
    assert viewpoint_utility(depth, FOCAL) == pytest.approx(expected.mean(), rel=1e-6)


def test_tilted_plane_normal_is_recovered():
    normal = np.array([math.sin(0.6), 0.0, math.cos(0.6)])
    normals = depth_normals(plane_depth(normal, 3.0), FOCAL)
    inner = normals[2:-2, 2:-2].reshape(-1, 3)
    np.testing.assert_allclose(np.abs(inner @ normal), 1.0, atol=1e-6)


def test_oblique_view_scores_lower_than_head_on():
    head_on = viewpoint_utility(plane_depth([0, 0, 1], 2.0), FOCAL)
    oblique = viewpoint_utility(plane_depth([math.sin(1.2), 0, math.cos(1.2)], 2.0), FOCAL)
    assert oblique < head_on - 0.3


def test_pixels_without_depth_are_left_out():
    depth = plane_depth([0, 0, 1], 2.0)
    depth[:, :30] = np.inf
    cosines = incidence_cosines(depth, FOCAL)
    assert 0 < len(cosines) < depth.size - 30 * depth.shape[0] + 1
    assert math.isnan(viewpoint_utility(np.full((5, 5), np.inf), FOCAL))


def test_bad_images_are_refused():
    with pytest.raises(InvalidInputError):
        viewpoint_utility(np.ones(5), FOCAL)
    with pytest.raises(InvalidInputError):
        viewpoint_utility(np.ones((5, 5)), 0.0)
