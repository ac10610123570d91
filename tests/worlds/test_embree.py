import numpy as np
import pytest
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from seminspect.worlds import RayCaster, raycast
from seminspect.worlds.embree import embree_library
from sim_worlds import car_world

needs_library = pytest.mark.skipif(
    embree_library() is None, reason="embreex's Embree library was not found"
)


def _rays(world, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Origins around the car and directions over the whole sphere (edges, grazing hits)."""
    rng = np.random.default_rng(seed)
    origins = rng.uniform((-6.0, -6.0, 0.2), (6.0, 6.0, 3.0), (count, 3))
    directions = rng.normal(size=(count, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return origins, directions.astype(np.float32)


def _embreex_reference(world, origins, directions, limits):
    """What ``embreex``'s own loop returns for the same shifted scene."""
    offset = world.raycaster.offset
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(
        scene=scene,
        vertices=(world.mesh.vertices - offset).astype(np.float32),
        indices=world.mesh.faces.astype(np.int32),
    )
    hits = scene.run(
        np.ascontiguousarray((origins - offset).astype(np.float32)),
        directions,
        dists=limits.astype(np.float32),
        output=1,
    )
    face = hits["primID"]
    return np.where(face == -1, np.float32(np.inf), hits["tfar"]), face


@needs_library
def test_compiled_casting_is_embreex_bit_for_bit() -> None:
    world = car_world(yaw=0.4)
    origins, directions = _rays(world, 20_000, seed=3)
    limits = np.random.default_rng(4).uniform(0.5, 12.0, len(origins))
    distance, face = world.raycaster.cast(origins, directions, limits)
    expected_distance, expected_face = _embreex_reference(world, origins, directions, limits)
    assert 0.2 < np.mean(face >= 0) < 0.95  # both hits and misses are compared
    np.testing.assert_array_equal(face, expected_face)
    np.testing.assert_array_equal(distance, expected_distance)


def test_fallback_through_embreex_matches_the_compiled_path(monkeypatch) -> None:
    world = car_world()
    origin = np.array([-8.0, 0.5, 1.0])
    _, directions = _rays(world, 10_000, seed=5)
    compiled = world.raycaster.cast(origin, directions, 9.0)
    monkeypatch.setattr(raycast, "embree_library", lambda: None)
    fallback = RayCaster(world.mesh.vertices, world.mesh.faces)
    assert fallback._compiled is None
    for threads in (1, 2):
        distance, face = fallback.cast(origin, directions, 9.0, threads=threads)
        np.testing.assert_array_equal(face, compiled[1])
        np.testing.assert_array_equal(distance, compiled[0])


def test_threads_shared_origins_and_limits_give_the_same_hits() -> None:
    world = car_world()
    _, directions = _rays(world, 3 * raycast.MIN_RAYS_PER_THREAD, seed=6)
    origin = np.array([-8.0, 0.5, 1.0])
    one = world.raycaster.cast(origin, directions, 7.5)
    split = world.raycaster.cast(origin, directions, 7.5, threads=3)
    per_ray = world.raycaster.cast(
        np.tile(origin, (len(directions), 1)), directions, np.full(len(directions), 7.5)
    )
    for distance, face in (split, per_ray):
        np.testing.assert_array_equal(face, one[1])
        np.testing.assert_array_equal(distance, one[0])
    assert np.all(one[0][one[1] >= 0] <= 7.5)
    assert np.all(np.isinf(one[0][one[1] < 0]))
