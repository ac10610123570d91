"""The frontier explorer of 000 Table 6 on the small city: it maps, and never inspects."""

from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import SeminspectError
from seminspect.mapping.voxel import UNKNOWN
from seminspect.missions.xflie.config import make_config, resolve
from seminspect.missions.xflie.frontier import FrontierMission
from seminspect.missions.xflie.run import build_mission, run_mission

pytestmark = pytest.mark.slow


def frontier_config(budget: float) -> dict:
    return {"world": "city", "scenario": "small", "planner": "frontier", "time_budget_s": budget}


def known_cells(mission: FrontierMission) -> int:
    return int(np.count_nonzero(mission.occupancy.states != UNKNOWN))


def test_each_frontier_hop_maps_more_of_the_site() -> None:
    mission, _ = build_mission(resolve(make_config(frontier_config(300))), None)
    assert isinstance(mission, FrontierMission)
    mission.navigator.sense_lidar()
    mission.exploration.survey()
    known = [known_cells(mission)]
    start = mission.platform.position
    for _ in range(2):
        assert mission.explore()
        known.append(known_cells(mission))
    assert known[0] < known[1] < known[2]
    assert np.linalg.norm((mission.platform.position - start)[:2]) > 3.0
    assert len(mission.frontiers.spent) >= 2


def test_the_explorer_never_inspects_and_is_scored_on_what_it_found(tmp_path: Path) -> None:
    result = run_mission(make_config(frontier_config(150)), tmp_path / "run")
    metrics = result.metrics
    assert result.state == "completed" and metrics is not None
    assert metrics.stop_reason in {"time budget spent", "no frontier left"}
    assert metrics.targets.inspected == 0 and metrics.table3.level == (0, 0)
    assert metrics.mission.level_endings.similarity == metrics.mission.level_endings.cap == 0
    events = (tmp_path / "run" / "events.jsonl").read_text()
    assert '"frontier"' in events and '"inspected"' not in events
    # Table 6 columns come from the targets found (the paper scores GBPlanner2.0 that way).
    assert metrics.targets.matched >= 1
    assert metrics.table6.localisation_rmse_m is not None
    assert metrics.table6.bbox_volume_m3 > 0
    assert metrics.mission.planning_wall_s > 0


def test_an_unknown_planner_is_one_readable_error() -> None:
    with pytest.raises(SeminspectError, match="planner"):
        make_config(frontier_config(100) | {"planner": "gbplanner"})


def test_frontiers_it_may_not_keep_are_never_tried() -> None:
    mission, _ = build_mission(resolve(make_config(frontier_config(300))), None)
    assert isinstance(mission, FrontierMission)
    mission.navigator.sense_lidar()
    mission.exploration.survey()
    start = mission.platform.position
    assert not mission.explore(keep=lambda goal: False)
    assert not mission.frontiers.spent
    np.testing.assert_array_equal(mission.platform.position, start)
    assert mission.explore(keep=lambda goal: True)  # there were frontiers to refuse
