"""The planning study's city missions: configured as the paper ran them, reused when complete,
and read back as Table 6's columns."""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.missions.xflie import sweep
from seminspect.missions.xflie.layout import reusable_mission
from seminspect.runs.directory import RunDirectory
from seminspect.studies.xflie.missions import MissionOutcome, ensure_run, study_config


def _fake_run(root: Path, state: str = "completed", **changes) -> Path:
    config = study_config("small").model_copy(update=changes)
    run = RunDirectory(root)
    run.write_config(config.model_dump(mode="json"))
    run.write_status(state)
    save_map(root / "map.npz", VoxelMap.empty([0, 0, 0], [1, 1, 1], 0.5))
    return root


def test_only_a_complete_run_of_the_same_configuration_is_reused(tmp_path, monkeypatch) -> None:
    config = study_config("small")
    assert reusable_mission(_fake_run(tmp_path / "same"), config)
    assert not reusable_mission(_fake_run(tmp_path / "stopped", "interrupted"), config)
    assert not reusable_mission(_fake_run(tmp_path / "other", seed=3), config)
    assert not reusable_mission(tmp_path / "missing", config)
    # ensure_run reuses the complete run under its study name, without running anything
    monkeypatch.setattr(sweep, "run_mission", lambda *a, **k: pytest.fail("ran"))
    complete = _fake_run(tmp_path / "city-small-seed0-hierarchical")
    assert ensure_run(config, tmp_path) == complete
    stray = tmp_path / "city-small-seed0-volumetric-charged"
    stray.write_text("a file where the run would go\n")
    with pytest.raises(InvalidInputError, match="not a run directory"):
        ensure_run(study_config("small", "volumetric", table6=True), tmp_path)


def test_an_unfinished_study_run_is_run_again(tmp_path, monkeypatch) -> None:
    calls = []
    ran = SimpleNamespace(stop_signal=None)  # a mission that ran to its end
    monkeypatch.setattr(sweep, "run_mission", lambda c, out, **k: calls.append(out) or ran)
    stale = _fake_run(tmp_path / "city-small-seed0-hierarchical", "interrupted")
    assert ensure_run(study_config("small"), tmp_path) == stale
    assert calls == [stale]  # the mission's claim clears the stale run's files


def test_table_6_runs_charge_planning_under_the_papers_budget() -> None:
    assert study_config("large").time_budget_s == 3600.0  # the mission default
    table6 = study_config("large", "volumetric", table6=True)
    assert table6.time_budget_s == 2800.0 and table6.charge_planning_time
    assert study_config("medium", table6=True, seed=2).seed == 2
    with pytest.raises(InvalidInputError, match="unknown city scenario 'huge'"):
        study_config("huge")


@pytest.mark.slow
def test_mission_outcomes_are_read_from_the_metrics(small_mission_dir: Path) -> None:
    outcome = MissionOutcome.read(small_mission_dir, "small", "hierarchical")
    assert outcome.inspected >= 3 and outcome.sim_time_s > 0 and outcome.planning_wall_s > 0
    assert outcome.seed == 0 and len(outcome.inspected_errors) == outcome.inspected
    assert max(outcome.inspected_errors.values()) < 1.0
    assert outcome.planning_load_pct == pytest.approx(
        100 * outcome.planning_wall_s / outcome.sim_time_s
    )


@pytest.mark.slow
def test_the_frontier_explorer_is_read_as_scored_on_the_targets_it_found(tmp_path: Path) -> None:
    config = study_config("small", "frontier", table6=True).model_copy(
        update={"time_budget_s": 100.0}
    )
    run_dir = ensure_run(config, tmp_path)
    outcome = MissionOutcome.read(run_dir, "small", "frontier")
    assert run_dir.name == "city-small-seed0-frontier-charged"
    assert outcome.inspected == 0 and outcome.found >= 1
    assert len(outcome.inspected_errors) == outcome.found  # every found target is scored
    assert outcome.rmse_m == pytest.approx(
        math.sqrt(np.mean(np.square(list(outcome.inspected_errors.values()))))
    )
