"""A small aerial mission around one collapsed building (000 Sec VI-B at a tenth of the size).

The aerial robot must inspect the building without touching it, register it as one target
whose refined centre lies within 1 m of the true footprint's, and leave windows, rubble and
people in its Feature layer for operator queries.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seminspect.graphs.lsg.model import TargetStatus
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.run import MissionResult, run_mission
from seminspect.planning.hierarchical import HierarchicalPlanner

#: Two levels and no frontier hops after the inspection keep the mission short.
CONFIG = {
    "world": "collapsed-buildings",
    "scenario": "small",
    "seed": 0,
    "inspection": {"d_view": 4.0, "max_levels": 2, "save_images": False},
    "exploration": {"frontier_max_hops": 0},
}


pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def aerial_mission(tmp_path_factory: pytest.TempPathFactory) -> MissionResult:
    out: Path = tmp_path_factory.mktemp("aerial") / "run"
    return run_mission(make_config(CONFIG), out)


def test_the_aerial_robot_inspects_the_building_without_touching_it(aerial_mission) -> None:
    metrics = aerial_mission.metrics
    assert aerial_mission.state == "completed" and metrics is not None
    assert aerial_mission.mission.config.mode == "aerial"
    assert metrics.mission.collisions == 0  # no motion stopped by an obstacle
    (building,) = aerial_mission.mission.graph.targets()
    assert building.status is TargetStatus.INSPECTED and len(building.levels) == 2


def test_the_building_is_one_target_centred_within_a_metre(aerial_mission) -> None:
    targets = aerial_mission.metrics.targets
    assert (targets.true, targets.in_graph, targets.false_targets) == (1, 1, 0)
    (match,) = targets.matches
    assert match.inspected and match.horizontal_error <= 1.0


def test_windows_and_rubble_on_the_building_answer_queries(aerial_mission) -> None:
    graph = aerial_mission.mission.graph
    (building,) = graph.targets()
    features = {f.label: f for level in building.levels for p in level.poses for f in p.features}
    assert {"window", "rubble"} <= set(features)
    window = features["window"]
    level = next(lv for lv in building.levels if any(p.id == window.pose_id for p in lv.poses))
    plan = HierarchicalPlanner(graph).query(f"Visit {window.name} in {level.name} of {building.id}")
    assert window.id in (plan.goal_id, plan.terminal_id) and len(plan.waypoints) >= 2


def test_the_buildings_surface_coverage_is_reported_on_its_own(aerial_mission) -> None:
    t6 = aerial_mission.metrics.table6
    (building,) = aerial_mission.mission.graph.targets()
    assert set(t6.surface_coverage_by_target_pct) == {building.id}
    assert t6.surface_coverage_by_target_pct[building.id] == pytest.approx(t6.surface_coverage_pct)
    assert 0 < t6.surface_coverage_pct <= 100
    summary = (aerial_mission.run_dir / "summary.md").read_text()
    assert f"| {t6.surface_coverage_pct:.1f} |" in summary.split("## Targets")[1]


def test_the_robot_flies_back_down_to_level_0_after_the_building(aerial_mission) -> None:
    (building,) = aerial_mission.mission.graph.targets()
    entry_height = building.levels[0].position[2]
    assert building.levels[-1].position[2] > entry_height + 1.0  # it climbed
    events = [e for e in aerial_mission.run_dir.joinpath("events.jsonl").read_text().splitlines()]
    descents = [json.loads(e) for e in events if '"descended"' in e]
    assert [d["reached"] for d in descents] == [True]
    assert abs(descents[0]["height"] - entry_height) < 0.5
