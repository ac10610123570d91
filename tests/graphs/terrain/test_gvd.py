import networkx as nx
import numpy as np

from seminspect.graphs.terrain.gvd import build_gvd, clean_grid


def _gvd(mask: np.ndarray):
    return build_gvd(
        mask,
        smoothing_cells=1,
        min_patch_cells=4,
        min_branch_cells=4,
        deviation_cells=1.5,
        length_cells=8.0,
        max_iterations=25,
    )


def _graph(result) -> nx.Graph:
    graph = nx.Graph()
    graph.add_nodes_from(range(len(result.nodes)))
    graph.add_edges_from((a, b) for a, b, _ in result.edges)
    return graph


def test_straight_corridor_gives_a_chain_along_its_centre_line() -> None:
    mask = np.zeros((14, 70), bool)
    mask[4:10, 3:67] = True  # rows 4..9: centre line between rows 6 and 7
    result = _gvd(mask)
    graph = _graph(result)
    assert nx.is_connected(graph) and nx.is_tree(graph)
    assert max(d for _, d in graph.degree()) <= 2  # a chain
    assert len(result.nodes) >= 64 / 8
    assert np.all(np.abs(result.nodes[:, 0] - 6.5) <= 1.5)
    lengths = [length for _, _, length in result.edges]
    assert max(lengths) <= 8.0 + 1.5


def test_t_junction_gives_one_junction_node() -> None:
    mask = np.zeros((44, 54), bool)
    mask[3:10, 3:51] = True
    mask[3:41, 24:31] = True
    graph = _graph(_gvd(mask))
    assert nx.is_connected(graph)
    assert sum(1 for _, d in graph.degree() if d >= 3) == 1
    assert sum(1 for _, d in graph.degree() if d == 1) == 3


def test_ring_gives_a_cycle() -> None:
    yy, xx = np.mgrid[0:44, 0:44]
    radius = np.hypot(yy - 21.5, xx - 21.5)
    result = _gvd((radius > 11) & (radius < 19))
    graph = _graph(result)
    assert nx.is_connected(graph)
    cycles = nx.cycle_basis(graph)
    assert any(len(cycle) >= 4 for cycle in cycles)
    distances = np.hypot(result.nodes[:, 0] - 21.5, result.nodes[:, 1] - 21.5)
    assert np.all(np.abs(distances - 15) <= 2.5)  # nodes on the ring's middle circle


def test_square_ring_without_corners_still_becomes_a_cycle() -> None:
    mask = np.zeros((34, 34), bool)
    mask[3:31, 3:31] = True
    mask[11:23, 11:23] = False
    graph = _graph(_gvd(mask))
    assert nx.cycle_basis(graph)


def test_cleaning_fills_holes_and_drops_specks() -> None:
    mask = np.zeros((30, 30), bool)
    mask[5:20, 5:20] = True
    mask[12, 12] = False  # a misclassified cell inside
    mask[27, 27] = True  # an isolated speck
    cleaned = clean_grid(mask, smoothing_cells=1, min_patch_cells=9)
    assert cleaned[12, 12] and not cleaned[27, 27]
    assert cleaned[6:19, 6:19].all() and cleaned.sum() >= 15 * 15 - 4  # only corners rounded


def test_empty_grid_has_no_places() -> None:
    result = _gvd(np.zeros((10, 10), bool))
    assert result.nodes.shape == (0, 2) and result.edges == []
