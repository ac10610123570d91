from seminspect.graphs.lsg.io import graph_document
from seminspect.graphs.lsg.synthetic import synthetic_graph


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
