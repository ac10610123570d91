import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.semantic_cloud import (
    CameraSegmentation,
    SemanticCloud,
    fuse_scan,
    load_cloud,
    save_cloud,
)


def test_running_mean_over_views_and_new_points() -> None:
    cloud = SemanticCloud.empty(2, "test")
    points = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    cloud.integrate(points, [[1.0, 0.0], [0.0, 1.0]], radius=0.1)
    stats = cloud.integrate(points + 0.01, [[0.0, 1.0], [0.0, 1.0]], radius=0.1)
    assert (stats.associated, stats.added) == (2, 0)
    stats = cloud.integrate([[0.0, 0.0, 0.05], [9.0, 9.0, 9.0]], [[1.0, 1.0], [1.0, 0.0]], 0.1)
    assert (stats.associated, stats.added) == (1, 1)
    assert cloud.counts.tolist() == [3, 2, 1]
    np.testing.assert_allclose(cloud.embeddings[0], [2 / 3, 2 / 3], atol=1e-6)
    np.testing.assert_allclose(cloud.embeddings[1], [0.0, 1.0])
    np.testing.assert_allclose(cloud.points[0], [0.0, 0.0, 0.0])  # map points do not move


@settings(max_examples=25, deadline=None)
@given(st.lists(st.lists(st.integers(0, 3), min_size=1, max_size=4, unique=True), max_size=6))
def test_embedding_is_the_mean_of_every_observation(views: list[list[int]]) -> None:
    # each view sees every anchor at most once; later views associate with the first one
    anchors = np.array([[0.0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]])
    rng = np.random.default_rng(len(views))
    cloud = SemanticCloud.empty(3, "test")
    observed: dict[int, list[np.ndarray]] = {}
    for view in views:
        embeddings = rng.normal(size=(len(view), 3)).astype(np.float32)
        cloud.integrate(anchors[view] + rng.uniform(-0.05, 0.05, (len(view), 3)), embeddings, 0.5)
        for anchor, embedding in zip(view, embeddings, strict=True):
            observed.setdefault(anchor, []).append(embedding)
    assert len(cloud) == len(observed)
    for row, point in enumerate(cloud.points):
        anchor = int(np.argmin(np.linalg.norm(anchors - point, axis=1)))
        assert cloud.counts[row] == len(observed[anchor])
        np.testing.assert_allclose(
            cloud.embeddings[row], np.mean(observed[anchor], axis=0), atol=1e-5
        )


def _segmentation() -> CameraSegmentation:
    ids = np.full((40, 60), -1)
    ids[:, :30] = 0  # left half: segment 0
    ids[:, 30:] = 1  # right half: segment 1
    ids[:5] = -1  # top rows unsegmented
    K = np.array([[50.0, 0, 30], [0, 50.0, 20], [0, 0, 1]])
    # sensor x forward, y left, z up -> camera x right, y down, z forward
    T = np.array([[0.0, -1, 0, 0], [0, 0, -1, 0], [1, 0, 0, 0], [0, 0, 0, 1]])
    return CameraSegmentation(ids, np.eye(2, dtype=np.float32), K, T)


def test_scan_points_take_the_segment_they_project_into() -> None:
    cloud = SemanticCloud.empty(2, "test")
    points = np.array(
        [
            [5.0, 1.0, 0.0],  # ahead, to the left -> left half of the image
            [5.0, -1.0, 0.0],  # ahead, to the right
            [-5.0, 0.0, 0.0],  # behind the camera
            [5.0, 0.0, 2.0],  # above: top rows, no segment
            [5.0, 20.0, 0.0],  # outside the image
        ]
    )
    pose = np.eye(4)
    pose[:3, 3] = [100.0, 0.0, 0.0]
    stats = fuse_scan(cloud, points, pose, _segmentation(), radius=0.1)
    assert (stats.associated, stats.added) == (0, 2)
    np.testing.assert_allclose(cloud.points, points[:2] + np.array([100.0, 0, 0]))
    np.testing.assert_allclose(cloud.embeddings, [[1.0, 0.0], [0.0, 1.0]])


def test_bad_inputs_are_refused() -> None:
    cloud = SemanticCloud.empty(2, "test")
    with pytest.raises(InvalidInputError, match="radius"):
        cloud.integrate([[0.0, 0, 0]], [[1.0, 0]], radius=0.0)
    with pytest.raises(InvalidInputError, match="NaN"):
        cloud.integrate([[np.nan, 0, 0]], [[1.0, 0]], radius=1.0)
    with pytest.raises(InvalidInputError, match="shape"):
        cloud.integrate([[0.0, 0, 0]], [[1.0, 0, 0]], radius=1.0)
    with pytest.raises(InvalidInputError, match="rigid"):
        fuse_scan(cloud, [[1.0, 0, 0]], np.ones((4, 4)), _segmentation(), radius=1.0)


def test_save_load_round_trip_and_broken_files(tmp_path) -> None:
    cloud = SemanticCloud(np.eye(3), np.eye(3, dtype=np.float32), np.array([1, 2, 3]), "enc")
    path = save_cloud(tmp_path / "cloud.npz", cloud)
    again = load_cloud(path)
    np.testing.assert_array_equal(again.points, cloud.points)
    np.testing.assert_array_equal(again.counts, [1, 2, 3])
    assert again.encoder == "enc"
    broken = tmp_path / "broken.npz"
    broken.write_bytes(path.read_bytes()[:100])
    with pytest.raises(FileFormatError, match="npz"):
        load_cloud(broken)
    other = tmp_path / "other.npz"
    np.savez(other, points=np.zeros((1, 3)))
    with pytest.raises(FileFormatError, match="not a seminspect"):
        load_cloud(other)
    with pytest.raises(FileFormatError, match="no such"):
        load_cloud(tmp_path / "missing.npz")


def test_growing_cloud_matches_a_plain_running_mean() -> None:
    # thousands of points: the buffers grow on the way, and later views put one or two scan
    # points on a map point
    rng = np.random.default_rng(3)
    grid = np.stack(np.meshgrid(np.arange(60.0), np.arange(60.0), [0.0]), -1).reshape(-1, 3)
    cloud = SemanticCloud.empty(4, "test")
    sums, counts = np.zeros((len(grid), 4)), np.zeros(len(grid))
    for view in range(6):
        if view == 0:  # every anchor once, so that later duplicates have a map point to join
            seen = rng.permutation(len(grid))
        else:
            seen = rng.choice(len(grid), 1500, replace=False)
            seen = np.concatenate([seen, seen[:400]])
        rows = rng.normal(size=(seen.size, 4)).astype(np.float32)
        cloud.integrate(grid[seen] + rng.uniform(-0.1, 0.1, (seen.size, 3)), rows, radius=0.3)
        np.add.at(sums, seen, rows)
        np.add.at(counts, seen, 1)
    assert len(cloud) == np.count_nonzero(counts)
    anchor = np.round(cloud.points[:, 1]).astype(int) * 60 + np.round(cloud.points[:, 0]).astype(
        int
    )
    np.testing.assert_array_equal(cloud.counts, counts[anchor])
    np.testing.assert_allclose(cloud.embeddings, sums[anchor] / counts[anchor, None], atol=1e-5)


def test_depth_image_hides_points_the_camera_cannot_see() -> None:
    base = _segmentation()
    depth = np.full(base.segment_ids.shape, 5.0, dtype=np.float32)
    occluded = CameraSegmentation(base.segment_ids, base.embeddings, base.K,
                                  base.T_camera_sensor, depth=depth)  # fmt: skip
    points = np.array([[5.0, 1.0, 0.0], [9.0, -1.8, 0.0], [5.3, -1.0, 0.0]])
    cloud = SemanticCloud.empty(2, "test")
    stats = fuse_scan(cloud, points, np.eye(4), occluded, radius=0.1)
    # the point 9 m away lies behind the 5 m surface the camera sees in its pixel
    assert (stats.associated, stats.added) == (0, 2)
    np.testing.assert_allclose(cloud.points, points[[0, 2]])
    with pytest.raises(InvalidInputError, match="depth image"):
        CameraSegmentation(base.segment_ids, base.embeddings, base.K, base.T_camera_sensor,
                           depth=depth[:3])  # fmt: skip
    with pytest.raises(InvalidInputError, match="tolerances"):
        CameraSegmentation(base.segment_ids, base.embeddings, base.K, base.T_camera_sensor,
                           depth=depth, depth_tolerance=-1.0)  # fmt: skip


def test_source_record_round_trips_and_is_checked(tmp_path) -> None:
    source = {"world": {"name": "outdoor", "scenario": "small", "seed": 2}, "frames": 7}
    cloud = SemanticCloud(np.eye(3), np.eye(3, dtype=np.float32), np.ones(3, int), "enc", source)
    again = load_cloud(save_cloud(tmp_path / "cloud.npz", cloud))
    assert again.source == source
    cloud.source = {"bad": object()}
    with pytest.raises(InvalidInputError, match="not JSON"):
        save_cloud(tmp_path / "bad.npz", cloud)
    arrays = dict(np.load(tmp_path / "cloud.npz"))
    arrays["source"] = np.array("[1, 2]")
    np.savez(tmp_path / "hostile.npz", **arrays)
    with pytest.raises(FileFormatError, match="source record"):
        load_cloud(tmp_path / "hostile.npz")
