from itertools import pairwise

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seminspect.core.errors import InvalidInputError
from seminspect.planning.graph_astar import CsrGraph, shortest_path


@st.composite
def geometric_graphs(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = draw(st.integers(2, 25))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    coords = rng.uniform(0, 50, (n, 3))
    pairs = {
        tuple(sorted(rng.choice(n, 2, replace=False))) for _ in range(draw(st.integers(1, 3 * n)))
    }
    edges = np.array(sorted(pairs))
    straight = np.linalg.norm(coords[edges[:, 0]] - coords[edges[:, 1]], axis=1)
    detour = rng.uniform(1.0, 1.5, len(edges))  # weights never below the straight line
    return coords, edges, straight * detour


@settings(max_examples=80, deadline=None)
@given(geometric_graphs(), st.data())
def test_astar_and_dijkstra_match_networkx(graph, data) -> None:
    coords, edges, weights = graph
    csr = CsrGraph.from_edges(coords, edges, weights)
    reference = nx.Graph()
    reference.add_nodes_from(range(len(coords)))
    reference.add_weighted_edges_from(
        (int(a), int(b), float(w)) for (a, b), w in zip(edges, weights, strict=True)
    )
    source = data.draw(st.integers(0, len(coords) - 1))
    target = data.draw(st.integers(0, len(coords) - 1))
    for heuristic in (True, False):
        cost, path, _ = shortest_path(csr, source, target, heuristic)
        if nx.has_path(reference, source, target):
            assert cost == pytest.approx(nx.dijkstra_path_length(reference, source, target))
            assert path[0] == source and path[-1] == target
            walked = sum(reference.edges[int(a), int(b)]["weight"] for a, b in pairwise(path))
            assert walked == pytest.approx(cost)
        else:
            assert cost == np.inf and path.size == 0


def test_the_heuristic_settles_fewer_nodes_on_a_long_corridor() -> None:
    coords = np.column_stack([np.arange(200.0), np.zeros(200), np.zeros(200)])
    edges = np.column_stack([np.arange(199), np.arange(1, 200)])
    csr = CsrGraph.from_edges(coords, edges, np.ones(199))
    _, _, with_h = shortest_path(csr, 100, 110, heuristic=True)
    _, _, without = shortest_path(csr, 100, 110, heuristic=False)
    assert with_h == 11 and without > 15


def test_invalid_graphs_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="does not exist"):
        CsrGraph.from_edges(np.zeros((2, 3)), [(0, 2)], [1.0])
    with pytest.raises(InvalidInputError, match="non-negative"):
        CsrGraph.from_edges(np.zeros((2, 3)), [(0, 1)], [-1.0])
    with pytest.raises(InvalidInputError, match="out of range"):
        shortest_path(CsrGraph.from_edges(np.zeros((2, 3)), [(0, 1)], [1.0]), 0, 5)
