import numpy as np

from seminspect.graphs.lsg.io import graph_document
from seminspect.graphs.lsg.synthetic import VEHICLE_SIZE, synthetic_graph, synthetic_layout


def test_synthetic_graphs_are_complete_and_deterministic() -> None:
    graph = synthetic_graph(7, seed=3, poses_per_level=5, levels=2)
    stats = graph.population()
    assert stats.targets_detected == stats.targets_inspected == 7
    assert stats.level.nodes == 7 * 3  # each target + its two levels
    assert stats.pose.nodes == 7 * 2 * 6  # each level + its five poses
    assert graph_document(graph) == graph_document(
        synthetic_graph(7, seed=3, poses_per_level=5, levels=2)
    )
    assert graph_document(graph) != graph_document(
        synthetic_graph(7, seed=4, poses_per_level=5, levels=2)
    )


def test_the_layout_is_where_the_graph_put_its_vehicles() -> None:
    graph = synthetic_graph(9, seed=2, poses_per_level=6)
    centres, labels = synthetic_layout(9, seed=2)
    assert [t.label for t in graph.targets()] == labels
    for target, centre, label in zip(graph.targets(), centres, labels, strict=True):
        half_length, half_width, _ = VEHICLE_SIZE[label]
        ring = np.array([p.position for p in target.levels[0].poses])
        distance = np.linalg.norm(ring[:, :2] - centre[:2], axis=1)
        np.testing.assert_allclose(distance, np.hypot(half_length, half_width) + 2.5)
