import numpy as np
from scipy.spatial import cKDTree

from fake_platform import FakePlatform, fake_context
from seminspect.mapping.voxel import OCCUPIED
from seminspect.missions.xflie.inspection import platform_vfov
from seminspect.missions.xflie.surface import (
    ATTACHED,
    MAPPED_REACH,
    MIN_VIEW_STEP,
    PointSet,
    SurfaceTracker,
    first_of_each_row,
)
from seminspect.perception.observation import Observation
from seminspect.planning.view_planner import ViewConstraints


def tracker(platform: FakePlatform | None = None, settings=None) -> SurfaceTracker:
    ctx, _ = fake_context(platform, settings=settings)
    view = ViewConstraints(
        d_view=2.5,
        overlap_h=0.6,
        overlap_v=0.6,
        hfov_deg=ctx.params.fov_deg,
        vfov_deg=platform_vfov(ctx.params),
    )
    return SurfaceTracker(ctx, view)


def wall(x: float = 3.0) -> np.ndarray:
    """Points of a 4 m wide, 1.5 m high wall facing the robot."""
    ys, zs = np.meshgrid(np.linspace(-2, 2, 21), np.linspace(0.2, 1.5, 7))
    return np.column_stack([np.full(ys.size, x), ys.ravel(), zs.ravel()])


def test_a_point_set_keeps_one_point_per_voxel_and_answers_radius_queries() -> None:
    points = PointSet(0.2)
    points.add(np.array([[0.01, 0.01, 0.01], [0.05, 0.05, 0.05], [1.0, 0.0, 0.0]]))
    assert points.size == 2
    near = points.near(np.array([[0.0, 0.0, 0.3], [3.0, 0.0, 0.0]]), 0.5)
    assert near.tolist() == [True, False]


def test_radius_queries_answer_as_the_whole_tree_does_near_and_far() -> None:
    """Queries outside the set's box, on its edge and across it give the tree's own answers."""
    rng = np.random.default_rng(1)
    cloud = PointSet(0.1)
    cloud.add(rng.uniform([0, 0, 0], [2, 1, 1], (500, 3)))
    queries = np.vstack(
        [
            rng.uniform(-3, 5, (4000, 3)),
            cloud.points[:50] + np.array([0.5, 0.0, 0.0]),  # the radius away along x
            cloud.points[:50] + np.array([0.5 + 1e-12, 0.0, 0.0]),
        ]
    )
    for radius in (0.05, 0.5, 2.0):
        distance, _ = cKDTree(cloud.points).query(queries, distance_upper_bound=radius)
        expected = np.isfinite(distance)
        assert 0 < expected.sum() < len(queries)
        np.testing.assert_array_equal(cloud.near(queries, radius), expected)


def test_adding_views_keeps_the_first_point_of_each_voxel_in_order() -> None:
    """The set grown view by view equals deduplicating all the points at once."""
    rng = np.random.default_rng(0)
    batches = [rng.uniform(-1.0, 1.0, (n, 3)) for n in (300, 0, 500, 200)]
    batches.append(batches[0][:50] + 0.01)  # revisits voxels already held
    grown = PointSet(0.2)
    for batch in batches:
        grown.add(batch)
    everything = np.vstack(batches)
    _, first = np.unique(np.floor(everything / 0.2).astype(np.int64), axis=0, return_index=True)
    np.testing.assert_array_equal(grown.points, everything[np.sort(first)])
    assert 0 < grown.size < len(everything)


def test_first_of_each_row_matches_numpy_unique_on_rows() -> None:
    rng = np.random.default_rng(3)
    for low, high, n in ((-5, 5, 400), (-1, 1, 50), (10**6, 10**6 + 3, 30), (0, 1, 1)):
        cells = rng.integers(low, high, (n, 3))
        _, first = np.unique(cells, axis=0, return_index=True)
        np.testing.assert_array_equal(first_of_each_row(cells), np.sort(first))
    assert first_of_each_row(np.empty((0, 3), dtype=np.int64)).size == 0


def test_lidar_returns_attached_to_the_target_join_its_surface() -> None:
    platform = FakePlatform()
    track = tracker(platform)
    target = wall()
    beside = np.array([[3.0, 2.0 + ATTACHED / 2, 0.5]])  # debris beside the wall
    far = np.array([[3.0, 8.0, 0.5]])
    ground = np.array([[3.0, 0.0, 0.05]])  # below min_height
    platform.scan_points = np.vstack([beside, far, ground])
    assert len(track.surface(target)) == len(target)  # no scan yet: the mask points only
    track.ctx.navigator.sense_lidar()
    track.target_cloud.add(target)
    surface = track.surface(target)
    assert len(surface) == len(target) + 1
    assert np.allclose(surface[-1], beside[0])


def test_only_the_surface_up_to_the_top_of_the_view_limits_the_level() -> None:
    track = tracker()
    tall = np.vstack([wall(), [[3.0, 0.0, 20.0]]])
    assert len(track.in_view(tall)) == len(tall) - 1
    assert len(track.in_view(tall[-1:])) == 1  # nothing below: keep what there is


def test_a_step_along_the_surface_keeps_the_viewing_distance() -> None:
    platform = FakePlatform(position=(0.5, 0.0, 0.7))
    track = tracker(platform)
    car = Observation([3.5, 0.0, 0.7], label="car", score=0.9, mask_area=1)
    track.ctx.graph.register_target(car)
    track.ctx.graph.optimise_targets()
    before = platform.position
    assert track.step_along(wall(), track.ctx.graph.target("car-0"))
    after = platform.position
    assert np.linalg.norm(after - before) > MIN_VIEW_STEP
    assert after[2] == before[2]  # a ground robot keeps its height
    nearest = np.min(np.linalg.norm(wall()[:, :2] - after[:2], axis=1))
    assert abs(nearest - 2.5) < 0.5


def test_a_view_move_too_short_to_matter_is_refused() -> None:
    platform = FakePlatform()
    track = tracker(platform)
    goal = platform.position + np.array([MIN_VIEW_STEP / 2, 0.0, 0.0])
    assert not track.move_to_view(goal, 0.0)
    assert platform.distance_travelled == 0.0


def mapped_around(mode: str) -> tuple[SurfaceTracker, np.ndarray]:
    """A robot at (0, 0, 2) whose map holds the ground, a slab stub 1.5 m beside it below its
    camera's view, and a wall beyond the mapped reach."""
    track = tracker(FakePlatform(position=(0.0, 0.0, 2.0)), settings={"mode": mode})
    occupancy = track.ctx.occupancy
    occupancy.states[:, :, 0] = OCCUPIED  # the ground, -0.25 to 0.25 m
    stub = occupancy.world_to_index([1.5, 0.0, 1.0])
    occupancy.states[tuple(stub)] = OCCUPIED
    far = occupancy.world_to_index([MAPPED_REACH * track.view.d_view + 1.0, 0.0, 1.0])
    occupancy.states[tuple(far)] = OCCUPIED
    return track, occupancy.index_to_world(stub)


def test_an_aerial_robot_keeps_its_distance_from_mapped_structure_below_its_view() -> None:
    track, stub = mapped_around("aerial")
    surface = track.surface(np.empty((0, 3)))
    np.testing.assert_allclose(surface, [stub])  # neither the ground nor the far wall
    ground, _ = mapped_around("ground")
    assert len(ground.surface(np.empty((0, 3)))) == 0  # ground robots: the target alone
