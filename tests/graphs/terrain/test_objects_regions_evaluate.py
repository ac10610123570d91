import numpy as np

from seminspect.graphs.terrain.evaluate import box_iou, match_boxes
from seminspect.graphs.terrain.objects import cluster_points
from seminspect.graphs.terrain.regions import agglomerate, task_distributions


def test_dbscan_separates_objects_and_drops_sparse_noise() -> None:
    rng = np.random.default_rng(0)
    first = rng.uniform([0, 0, 0], [4, 2, 1.5], (400, 3))
    second = rng.uniform([10, 0, 0], [14, 2, 1.5], (400, 3))
    noise = np.array([[30.0, 30, 0], [-20, 5, 0]])
    labels = cluster_points(np.vstack([first, second, noise]), eps=0.8, min_points=10, voxel=0.2)
    assert len(set(labels[:400])) == 1 and len(set(labels[400:800])) == 1
    assert labels[0] != labels[400] and labels[0] >= 0
    assert labels[-1] == -1 and labels[-2] == -1


def test_voxel_weights_keep_min_points_a_count_of_points() -> None:
    dense = np.zeros((12, 3)) + np.array([0.01, 0, 0])  # 12 points in one voxel
    assert np.all(cluster_points(dense, eps=0.5, min_points=10, voxel=0.2) == 0)
    assert np.all(cluster_points(dense[:5], eps=0.5, min_points=10, voxel=0.2) == -1)


def test_box_iou_and_matching() -> None:
    unit = (np.zeros(3), np.ones(3))
    half = (np.array([0.5, 0, 0]), np.array([1.5, 1, 1]))
    assert box_iou(unit, unit) == 1.0
    assert abs(box_iou(unit, half) - 1 / 3) < 1e-12
    far = (np.full(3, 5.0), np.full(3, 6.0))
    scores = match_boxes([unit, far], [half], threshold=0.3)
    assert (scores.matched, scores.precision, scores.recall) == (1, 0.5, 1.0)
    assert match_boxes([unit], [half], threshold=0.5).matched == 0


def test_bottleneck_merges_neighbours_with_the_same_task_only() -> None:
    # a chain of six primitives: three about prompt 0, then three about prompt 1
    similarity = np.array([[0.9, 0.1]] * 3 + [[0.1, 0.9]] * 3)
    py_x = task_distributions(similarity, null_similarity=0.2, top_k=2)
    np.testing.assert_allclose(py_x.sum(axis=1), 1.0)
    chain = [(i, i + 1) for i in range(5)]
    regions = agglomerate(py_x, chain, delta=0.05)
    assert regions.assignment.tolist() == [0, 0, 0, 1, 1, 1]
    assert regions.retained <= regions.information + 1e-9
    merged = agglomerate(py_x, chain, delta=10.0)
    assert len(set(merged.assignment.tolist())) == 1
    # without a link, identical primitives stay apart
    assert len(set(agglomerate(py_x, [], delta=10.0).assignment.tolist())) == 6


def test_null_task_claims_primitives_unrelated_to_every_prompt() -> None:
    py_x = task_distributions(np.array([[0.05, 0.1]]), null_similarity=0.2, top_k=2)
    assert py_x[0, 0] > 0.99
