import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.worlds import RayCaster
from sim_worlds import box_world


def test_first_hit_distances_faces_and_misses() -> None:
    world = box_world(lower=(4, -1, 0), upper=(6, 1, 2))
    caster = world.raycaster
    directions = np.array([[1, 0, 0], [0, 0, -1], [0, 0, 1], [1, 0, 0]], dtype=np.float32)
    origins = np.array([[0, 0, 1], [0, 0, 3], [0, 0, 1], [0, 5, 1]], dtype=float)
    distance, face = caster.cast(origins, directions)
    np.testing.assert_allclose(distance[:2], [4.0, 3.0], atol=1e-5)
    assert world.instances[world.face_instance[face[0]]].name == "crate-1"
    assert world.class_names[world.face_class[face[1]]] == "ground"
    assert face[2] == -1 and np.isinf(distance[2])
    assert face[3] == -1  # passes beside the crate, leaves the ground plane's edge


def test_max_range_per_ray_and_a_shared_origin() -> None:
    caster = box_world().raycaster
    directions = np.tile(np.array([[1, 0, 0]], dtype=np.float32), (3, 1))
    distance, face = caster.cast((0.0, 0.0, 1.0), directions, np.array([3.0, 4.5, 10.0]))
    assert face[0] == -1 and np.isinf(distance[0])
    np.testing.assert_allclose(distance[1:], 4.0, atol=1e-5)


def test_hits_written_into_given_buffers() -> None:
    caster = box_world().raycaster
    directions = np.array([[1, 0, 0], [0, 0, -1], [0, 0, 1]], dtype=np.float32)
    distance, face = np.full(3, np.nan, np.float32), np.full(3, 7, np.int32)
    written = caster.cast((0.0, 0.0, 1.0), directions, out=(distance, face))
    assert written[0] is distance and written[1] is face
    expected = caster.cast((0.0, 0.0, 1.0), directions)
    np.testing.assert_array_equal(distance, expected[0])
    np.testing.assert_array_equal(face, expected[1])
    with pytest.raises(InvalidInputError, match="contiguous"):
        caster.cast((0.0, 0.0, 1.0), directions, out=(distance.astype(np.float64), face))


def test_bad_rays_and_meshes_are_refused() -> None:
    caster = box_world().raycaster
    with pytest.raises(InvalidInputError):
        caster.cast(np.zeros((2, 3)), np.zeros((3, 3), dtype=np.float32))
    with pytest.raises(InvalidInputError):
        caster.cast((0, 0, 0), np.zeros((3, 2)))
    with pytest.raises(InvalidInputError):
        caster.cast((0, 0, 0), np.zeros((3, 3), dtype=np.float32), np.ones(2))
    with pytest.raises(InvalidInputError):
        RayCaster(np.zeros((3, 3)), np.zeros((0, 3), dtype=int))
