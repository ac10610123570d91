"""The planning study's pieces: query choice, run reuse, the per-query comparison."""

import math
from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.missions.xflie import sweep
from seminspect.perception.observation import Observation
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.runs.directory import RunDirectory, reusable_run
from seminspect.studies.xflie import study as planning_study
from seminspect.studies.xflie.comparison import HierarchicalTiming, VolumetricResult
from seminspect.studies.xflie.study import (
    MissionOutcome,
    PathCheck,
    QueryComparison,
    above_ground,
    compare_run,
    ensure_run,
    reachable_targets,
    select_queries,
    study_config,
)


def test_queries_spread_from_the_nearest_to_the_farthest_target() -> None:
    graph = synthetic_graph(12, seed=1)
    start = np.zeros(3)
    queries = select_queries(graph, start, 5)
    assert queries == select_queries(graph, start, 5)  # deterministic
    by_distance = sorted(graph.targets(), key=lambda t: np.linalg.norm(t.position - start))
    named = [q.rsplit(" of ", 1)[1] for q in queries]
    assert named[0] == by_distance[0].id and named[-1] == by_distance[-1].id
    assert len(set(named)) == 5
    planner = HierarchicalPlanner(graph)
    for text in queries:
        assert text.startswith("Visit ") and " in Level-0 of " in text
        assert planner.query(text, start).terminal_id is not None  # a feature, found


def test_few_targets_are_asked_for_several_features() -> None:
    graph = synthetic_graph(2, seed=3, parts_per_pose=3)
    queries = select_queries(graph, np.zeros(3), 9)
    assert len(queries) == len(set(queries)) == 9
    first = [q.split(" in ")[0].removeprefix("Visit ") for q in queries[:4]]
    assert all(name.endswith("-1") for name in first)  # every label's first feature first
    with pytest.raises(InvalidInputError, match="positive"):
        select_queries(graph, np.zeros(3), 0)


def _comparison(hp_s: float, vp_s: float, hp_m: float, vp_m: float) -> QueryComparison:
    timing = HierarchicalTiming(hp_s / 4, hp_s / 4, hp_s / 2, hp_s, 2 * hp_s, 5)
    answer = VolumetricResult(0.5, vp_s, vp_m, 10, 0.0, np.zeros((2, 3)))
    check = PathCheck(3, 4)
    return QueryComparison(
        "Visit x-1 in Level-0 of car-1", "car-1/Level-0/x-1", 10.0, timing, 5.0, hp_m, check,
        0.8 * hp_m, hp_s, check, (answer,), (check,),
    )  # fmt: skip


def test_ratios_divide_volumetric_by_hierarchical() -> None:
    q = _comparison(hp_s=1e-5, vp_s=1e-2, hp_m=12.0, vp_m=10.0)
    assert q.time_ratio(0.5) == pytest.approx(2000)  # against the searches (half of plan)
    assert q.time_ratio(0.5, "plan") == pytest.approx(1000)
    assert q.time_ratio(0.5, "query") == pytest.approx(500)
    assert q.time_ratio(0.5, "refined") == pytest.approx(1e-2 / 3e-5)
    assert q.length_ratio(0.5) == pytest.approx(1.2)
    assert q.length_ratio(0.5, refined=True) == pytest.approx(0.96)
    assert not q.hp_check.all_valid and PathCheck(2, 2).all_valid
    with pytest.raises(InvalidInputError, match=r"0\.7"):
        q.volumetric(0.7)


def test_the_ground_band_starts_above_the_maps_ground_cells() -> None:
    coarse = VoxelMap.empty([0, 0, -0.35], [10, 10, 5], 0.7)  # ground in the bottom layer
    assert above_ground((0.3, 1.2), coarse) == pytest.approx((0.35, 1.2), abs=1e-5)
    fine = VoxelMap.empty([0, 0, -0.2], [10, 10, 5], 0.4)
    assert above_ground((0.3, 1.2), fine) == (0.3, 1.2)


def _fake_run(root: Path, state: str = "completed", **changes) -> Path:
    config = study_config("small").model_copy(update=changes)
    run = RunDirectory(root)
    run.write_config(config.model_dump(mode="json"))
    run.write_status(state)
    save_map(root / "map.npz", VoxelMap.empty([0, 0, 0], [1, 1, 1], 0.5))
    return root


def test_only_a_complete_run_of_the_same_configuration_is_reused(tmp_path, monkeypatch) -> None:
    config = study_config("small")
    assert reusable_run(_fake_run(tmp_path / "same"), config)
    assert not reusable_run(_fake_run(tmp_path / "stopped", "interrupted"), config)
    assert not reusable_run(_fake_run(tmp_path / "other", seed=3), config)
    assert not reusable_run(tmp_path / "missing", config)
    # ensure_run reuses the complete run under its study name, without running anything
    monkeypatch.setattr(sweep, "run_mission", lambda *a, **k: pytest.fail("ran"))
    complete = _fake_run(tmp_path / "city-small-seed0-hierarchical")
    assert ensure_run(config, tmp_path) == complete
    stray = tmp_path / "city-small-seed0-volumetric-charged"
    stray.mkdir()
    with pytest.raises(InvalidInputError, match="not a run directory"):
        ensure_run(study_config("small", "volumetric", table6=True), tmp_path)


def test_an_unfinished_study_run_is_run_again(tmp_path, monkeypatch) -> None:
    calls = []
    monkeypatch.setattr(sweep, "run_mission", lambda c, out, **k: calls.append(out))
    stale = _fake_run(tmp_path / "city-small-seed0-hierarchical", "interrupted")
    (stale / "images").mkdir()
    assert ensure_run(study_config("small"), tmp_path) == stale
    assert calls == [stale] and not (stale / "images").exists()


def test_table_6_runs_charge_planning_under_the_papers_budget() -> None:
    assert study_config("large").time_budget_s == 3600.0  # the mission default
    table6 = study_config("large", "volumetric", table6=True)
    assert table6.time_budget_s == 2800.0 and table6.charge_planning_time
    assert study_config("medium", table6=True, seed=2).seed == 2
    with pytest.raises(InvalidInputError, match="unknown city scenario 'huge'"):
        study_config("huge")


@pytest.mark.slow
def test_a_run_is_compared_query_by_query(small_mission_dir: Path) -> None:
    result = compare_run(small_mission_dir, count=3, repeats=3, vp_repeats=1, resolutions=(0.5,))
    assert len(result.queries) == 3 and result.inspected_targets >= 3
    assert result.edge_check.all_valid and result.edge_check.segments > 40
    np.testing.assert_allclose(result.start, planning_study.final_pose(small_mission_dir))
    for q in result.queries:
        assert q.hp_check.all_valid and q.refined_check.all_valid
        assert q.refined_length_m <= q.hp_length_m + 1e-9
        vp = q.volumetric(0.5)
        assert vp.error is None and vp.length >= q.straight_m - 1.0
        assert math.isfinite(q.time_ratio(0.5, "query")) and q.hp.repeats == 3


@pytest.mark.slow
def test_the_full_volume_baseline_searches_every_height(small_mission_dir: Path) -> None:
    args = {"count": 2, "repeats": 1, "vp_repeats": 1, "resolutions": (0.5,)}
    ground = compare_run(small_mission_dir, **args)
    full = compare_run(small_mission_dir, volume="full", **args)
    assert ground.volume == "ground" and full.volume == "full"
    for flat, free in zip(ground.queries, full.queries, strict=True):
        assert flat.query == free.query and flat.hp_length_m == free.hp_length_m
        answer, check = free.volumetric(0.5), free.vp_checks[0]
        assert answer.error is None and check.segments == len(answer.waypoints) - 1
        # A 0.5 m grid keeps its clearance from cell centres: now and then a cell's worth short.
        assert check.valid >= 0.9 * check.segments
        # It flies no lower than the robot's centre, and up to where the map ends.
        assert answer.waypoints[:, 2].min() >= full.start[2] - 1e-6
    assert sum(q.vp_checks[0].segments for q in full.queries) > 10


@pytest.mark.slow
def test_an_unknown_volume_is_refused(small_mission_dir: Path) -> None:
    with pytest.raises(InvalidInputError, match="unknown volume 'sky'"):
        compare_run(small_mission_dir, volume="sky")
    with pytest.raises(InvalidInputError, match="unknown volume 'sky'"):
        planning_study.run_study(["small"], small_mission_dir.parent, volume="sky")


@pytest.mark.slow
def test_mission_outcomes_are_read_from_the_metrics(small_mission_dir: Path) -> None:
    outcome = MissionOutcome.read(small_mission_dir, "small", "hierarchical")
    assert outcome.inspected >= 3 and outcome.sim_time_s > 0 and outcome.planning_wall_s > 0
    assert outcome.seed == 0 and len(outcome.inspected_errors) == outcome.inspected
    assert max(outcome.inspected_errors.values()) < 1.0
    assert outcome.planning_load_pct == pytest.approx(
        100 * outcome.planning_wall_s / outcome.sim_time_s
    )


def test_queries_keep_to_targets_the_graph_joins_to_the_start() -> None:
    graph = LayeredSemanticGraph()
    for x in (0.0, 60.0):  # two cars, inspected, never joined in the Target layer
        graph.register_target(Observation([x, 0, 0.7], label="car", mask_area=1))
    graph.optimise_targets()
    for target, x in zip(graph.targets(), (0.0, 60.0), strict=True):
        graph.begin_inspection(target.id, Observation.view_pose([x - 3, 0, 0.7]))
        for dx, dy in ((0, 3), (3, 0), (0, -3)):
            graph.register_pose(Observation.view_pose([x + dx, dy, 0.7]))
            graph.register_feature(Observation([x + dx / 2, dy / 2, 0.7], label="hood"))
        graph.finish_inspection()
    planner = HierarchicalPlanner(graph)
    start = np.array([-5.0, 0.0, 0.7])
    assert reachable_targets(planner, start) == {"car-0"}
    queries = select_queries(graph, start, 4, reachable={"car-0"})
    assert queries and all(q.endswith("of car-0") for q in queries)
    assert any(q.endswith("of car-1") for q in select_queries(graph, start, 4))


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
