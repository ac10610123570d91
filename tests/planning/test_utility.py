"""000 eq (6), checked against hand-computed values."""

import math

import pytest

from seminspect.core.params import PRESETS
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.perception.observation import Observation
from seminspect.planning.utility import select_target, utility_terms

PARAMS = PRESETS["urban-simulated"]  # S_p=50, S_a=5, S_n=5, 640x480 images, epsilon=2 m


def graph_with(*targets: tuple[float, float, float]) -> LayeredSemanticGraph:
    graph = LayeredSemanticGraph(PARAMS, robot_position=[0, 0, 0])
    for x, y, area in targets:
        graph.register_target(Observation([x, y, 0], label="car", score=0.9, mask_area=area))
    graph.optimise_targets()
    return graph


def test_two_targets_by_hand() -> None:
    graph = graph_with((10, 0, 30720), (0, 20, 3072))
    best, terms = select_target(graph)
    d = math.hypot(10, 20)
    assert [t.proximity for t in terms] == pytest.approx([0.1, 0.05])
    assert [t.area for t in terms] == pytest.approx([0.1, 0.01])
    assert [t.centrality for t in terms] == pytest.approx([1 / d, 1 / d])
    assert terms[0].utility == pytest.approx(50 * 0.1 + 5 * 0.1 + 5 / d)  # 5.7236
    assert terms[1].utility == pytest.approx(50 * 0.05 + 5 * 0.01 + 5 / d)  # 2.7736
    assert best is terms[0]
    assert graph.target("car-0").utility == pytest.approx(terms[0].utility)


def test_centrality_is_the_mean_distance_to_the_other_uninspected_targets() -> None:
    terms = utility_terms(
        [0, 0, 0], graph_with((10, 0, 1), (20, 0, 1), (40, 0, 1)).targets(), PARAMS
    )
    assert terms[0].centrality == pytest.approx(1 / ((10 + 30) / 2))
    assert terms[1].centrality == pytest.approx(1 / ((10 + 20) / 2))


def test_a_single_target_and_a_robot_standing_on_it_stay_finite() -> None:
    graph = graph_with((0, 0, 1000))
    best, _ = select_target(graph)
    assert best is not None
    assert best.centrality == 0.0  # no other target to be central to
    assert best.proximity == pytest.approx(1 / PARAMS.epsilon)  # distance floored at epsilon
    assert math.isfinite(best.utility)


def test_nothing_to_select_and_ties_keep_registration_order() -> None:
    assert select_target(LayeredSemanticGraph()) == (None, [])
    best, _ = select_target(graph_with((10, 0, 100), (-10, 0, 100)))
    assert best is not None and best.target_id == "car-0"


def test_excluded_targets_are_not_candidates() -> None:
    graph = graph_with((10, 0, 30720), (0, 20, 3072))
    best, terms = select_target(graph, exclude={"car-0"})
    assert best is not None and best.target_id == "car-1" and len(terms) == 1
    assert terms[0].centrality == 0.0  # the only candidate left
