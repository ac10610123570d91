"""The semantic object's four shapes: 60 faces, outward triangles, analytic solids, bounds."""

import numpy as np
import pytest

from seminspect.missions.learning.env_config import TARGET_SHAPES
from seminspect.missions.learning.solids import solid_distance
from seminspect.missions.learning.targets import TARGET_FACES, make_target, revolve

ROOM = np.array([10.0, 10.0, 4.0])


def _targets(shape, seeds=range(5), room=ROOM):
    return [make_target(np.random.default_rng(seed), shape, room, 2.2) for seed in seeds]


def _on_surface(target):
    """Per triangle: all its corners on the object's surface (not hidden inside a T's joint)."""
    on = solid_distance(target.vertices, target.solids) > -1e-9
    return on[target.triangles].all(axis=1), on[target.triangles].any(axis=1)


def _normals(target):
    corners = target.vertices[target.triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2
    return corners.mean(axis=1), cross / (2 * area[:, None]), area


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_every_shape_has_60_faces_all_used_on_its_surface(shape):
    for target in _targets(shape):
        assert target.shape == shape
        assert sorted(set(target.faces.tolist())) == list(range(TARGET_FACES))
        assert len(target.faces) == len(target.triangles)
        # the mesh's vertices lie on the analytic solid's surface (or inside, at a T's joint)
        gap = solid_distance(target.vertices, target.solids)
        assert np.all(gap < 1e-9) and np.mean(gap > -1e-9) > 0.8
        # the bound holds the mesh, tightly
        assert np.all(target.vertices >= target.box[0] - 1e-9)
        assert np.all(target.vertices <= target.box[1] + 1e-9)
        np.testing.assert_allclose(target.vertices.min(axis=0)[2], 0.0, atol=1e-9)  # on the floor
        np.testing.assert_allclose(target.vertices.max(axis=0), target.box[1], atol=0.02)


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_triangles_face_out_of_the_object(shape):
    for target in _targets(shape):
        centre, normal, _ = _normals(target)
        on_surface, _ = _on_surface(target)  # a T-pipe's pipes hide parts of each other
        assert on_surface.mean() > 0.7
        # 6 cm: past a chord's sag below the curved surface, within the thinnest pipe
        outside = solid_distance(centre + 0.06 * normal, target.solids)
        inside = solid_distance(centre - 0.06 * normal, target.solids)
        assert np.all(outside[on_surface] > 0.0)
        assert np.all(inside[on_surface] < 0.0)


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_every_face_keeps_a_visible_part(shape):
    """No face lies wholly inside the object (a T-pipe's joint hides parts of faces)."""
    for target in _targets(shape, range(40)):
        _, visible = _on_surface(target)
        assert np.all(np.bincount(target.faces, visible, TARGET_FACES) > 0)


def test_the_analytic_solid_is_negative_inside_and_positive_outside():
    rng = np.random.default_rng(0)
    for shape in TARGET_SHAPES:
        target = _targets(shape, [1])[0]
        points = rng.uniform(target.box[0] - 0.3, target.box[1] + 0.3, (4000, 3))
        gap = solid_distance(points, target.solids)
        outside_box = np.any((points < target.box[0]) | (points > target.box[1]), axis=1)
        assert np.all(gap[outside_box] > 0.0)
        assert 0.05 < (gap < 0.0).mean() < 0.9  # some points are inside, most of the box's


def test_faces_of_a_shape_have_similar_areas():
    for shape, spread in (("sphere", 1.1), ("box", 4.5)):  # a sphere's bands: equal areas
        for target in _targets(shape):
            _, _, area = _normals(target)
            per_face = np.bincount(target.faces, area, TARGET_FACES)
            assert per_face.max() / per_face.min() < spread, shape


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_sizes_stay_in_scale_and_low_rooms_keep_a_metre_above(shape):
    for room in (ROOM, np.array([4.0, 4.0, 2.0])):
        for target in _targets(shape, range(20), room):
            width = target.box[1, :2] - target.box[0, :2]
            height = target.box[1, 2]
            assert 0.3 <= width.max() <= 2.4
            assert height <= room[2] - 1.0 + 1e-9
            assert target.radius >= width.max() / 2 - 1e-9  # it bounds the footprint
            assert np.all(target.box[0, :2] >= 0.0) and np.all(target.box[1, :2] <= room[:2])


def test_a_revolved_cap_and_side_face_out():
    """A closed unit cylinder: bottom outward, side, then the top inward (left: inside)."""
    profile = np.array([(0.0, -1.0), (1.0, -1.0), (1.0, 1.0), (0.0, 1.0)])
    vertices, triangles, ids = revolve(profile, 8, np.repeat([[0], [1], [2]], 8, axis=1))
    corners = vertices[triangles]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = np.einsum("ij,ij->i", normal, corners.mean(axis=1))
    assert np.all(outward > 0)
    assert len(vertices) == 1 + 8 + 8 + 1  # a radius-0 point is one vertex
    np.testing.assert_array_equal(np.bincount(ids), [8, 16, 8])
