import math

import numpy as np
import pytest

from seminspect.graphs.lsg.model import TargetNode, TargetStatus
from seminspect.missions.xflie.scoring import (
    TruthTarget,
    localisation_rmse,
    score_targets,
    scored_matches,
)


def node(name: str, label: str, x: float, y: float, inspected: bool = True) -> TargetNode:
    status = TargetStatus.INSPECTED if inspected else TargetStatus.DETECTED
    return TargetNode(name, label, 0, np.array([x, y, 1.0]), 1.0, 1.0, None, 0.0, status=status)


TRUTH = [
    TruthTarget("car-a", "car", np.array([0.0, 0.0, 0.75])),
    TruthTarget("car-b", "car", np.array([10.0, 0.0, 0.75])),
    TruthTarget("truck-c", "truck", np.array([0.0, 20.0, 1.6])),
]


def test_hungarian_matching_rates_and_rmse_by_hand() -> None:
    targets = [
        node("car-0", "car", 0.3, 0.4),  # 0.5 m from car-a
        node("car-1", "car", 10.0, 1.2),  # 1.2 m from car-b
        node("car-2", "car", 40.0, 0.0),  # nothing near: a false target
        node("truck-3", "truck", 0.0, 21.0, inspected=False),
    ]
    score = score_targets(targets, TRUTH)
    assert {(m.target_id, m.truth) for m in score.matches} == {
        ("car-0", "car-a"),
        ("car-1", "car-b"),
        ("truck-3", "truck-c"),
    }
    assert score.detected_pct == pytest.approx(100.0)
    assert score.inspected_pct == pytest.approx(200 / 3)
    assert score.false_targets == 1
    assert score.rmse() == pytest.approx(math.sqrt((0.5**2 + 1.2**2) / 2))
    assert score.rmse(horizontal=False) == pytest.approx(
        math.sqrt((0.5**2 + 0.25**2 + 1.2**2 + 0.25**2) / 2)
    )


def test_class_and_gate_block_matches() -> None:
    score = score_targets(
        [node("truck-0", "truck", 0.0, 0.0), node("car-1", "car", 5.0, 0.0)], TRUTH
    )
    assert score.matches == () and score.detected_pct == 0.0
    assert math.isnan(score.rmse())
    assert score_targets([], TRUTH).truths == 3


def test_an_explorer_is_scored_on_every_target_it_found() -> None:
    targets = [
        node("car-0", "car", 0.3, 0.4, inspected=False),  # 0.5 m from car-a
        node("car-1", "car", 10.0, 1.2, inspected=False),  # 1.2 m from car-b
        node("truck-2", "truck", 0.0, 21.0),  # 1.0 m from truck-c, inspected
    ]
    score = score_targets(targets, TRUTH)
    found = scored_matches(score.matches, inspecting=False)
    assert {m.target_id for m in found} == {"car-0", "car-1", "truck-2"}
    assert [m.target_id for m in scored_matches(score.matches, inspecting=True)] == ["truck-2"]
    assert localisation_rmse(found) == pytest.approx(math.sqrt((0.5**2 + 1.2**2 + 1.0**2) / 3))
    assert math.isnan(localisation_rmse([]))
