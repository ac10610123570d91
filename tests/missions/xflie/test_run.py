"""End to end: a small mission, its run directory, interruption and failure."""

import json
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import SeminspectError
from seminspect.core.io import read_versioned_json
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import EdgeKind
from seminspect.mapping.voxel import FREE, load_map
from seminspect.missions.xflie import XFlie, outputs
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.metrics import MissionMetrics
from seminspect.missions.xflie.run import run_mission
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.runs.trajectory import load_trajectory

pytestmark = pytest.mark.slow


def test_the_small_mission_finds_inspects_and_localises_every_car(small_mission) -> None:
    metrics = small_mission.metrics
    assert small_mission.state == "completed"
    assert metrics.table3.detected_pct == 100.0
    assert metrics.table3.inspected_pct == 100.0
    assert metrics.targets.false_targets == 0
    assert metrics.table6.localisation_rmse_m < 0.25  # 000 Table 6: 0.17-0.24 m
    assert metrics.mission.collisions == 0
    assert metrics.mission.level_endings.similarity >= 2  # eq (8) closes levels


def test_every_layer_is_populated_as_in_table_3(small_mission) -> None:
    t3 = small_mission.metrics.table3
    for layer in (t3.target, t3.level, t3.pose, t3.feature):
        assert layer[0] > 0 and layer[1] > 0, layer
    assert t3.pose[0] >= 3 * 15  # a ring of views around each of the three cars
    assert 15 < t3.reconciled_pct < 40
    graph = small_mission.graph
    for target in graph.targets():
        assert target.polygon is not None and len(target.levels) == 1
        assert len({f.label for p in target.levels[0].poses for f in p.features}) >= 8


def test_the_run_directory_is_complete_and_readable(small_mission_dir: Path) -> None:
    for name in (
        "config.json",
        "graph.json",
        "metrics.json",
        "summary.md",
        "status.json",
        "trajectory.csv",
        "events.jsonl",
    ):
        assert (small_mission_dir / name).stat().st_size > 0, name
    status = read_versioned_json(small_mission_dir / "status.json", "seminspect.run-status", [1])
    assert status["state"] == "completed"
    graph = load_graph(small_mission_dir / "graph.json")
    pose = graph.targets()[0].levels[0].poses[0]
    assert (small_mission_dir / pose.image).exists()  # images are referenced by path
    assert list((small_mission_dir / "snapshots").glob("graph-*.json"))
    events = [
        json.loads(line) for line in (small_mission_dir / "events.jsonl").read_text().splitlines()
    ]
    kinds = {e["event"] for e in events}
    assert {"detected", "selected", "arrived", "inspected", "level-complete", "utilities"} <= kinds
    trajectory = np.loadtxt(small_mission_dir / "trajectory.csv", delimiter=",", skiprows=1)
    assert trajectory.shape[1] == 9 and np.all(np.diff(trajectory[:, 0]) >= 0)


def test_metrics_json_reads_back_as_the_typed_metrics(small_mission, small_mission_dir) -> None:
    data = read_versioned_json(small_mission_dir / "metrics.json", "seminspect.run-metrics", [1])
    assert MissionMetrics.from_json(data) == small_mission.metrics
    assert set(data["mission"]) >= {"level_endings", "wall_time_by_category_s"}
    assert data["world"]["detector"] == "truth"  # which detector saw the run
    older = {**data, "world": {k: v for k, v in data["world"].items() if k != "detector"}}
    assert MissionMetrics.from_json(older).world.detector == "truth"  # before the seam


def test_operator_queries_are_answered_and_driven(small_mission) -> None:
    answers = {a.query: a for a in small_mission.answers}
    visit = answers["Visit car-0"]
    assert visit.reached and visit.path_length_m > 0 and visit.planning_time_s < 0.01
    observe = answers["Observe front-bumper-1 in Level-0 of car-1"]
    assert observe.goal == "car-1/Level-0/front-bumper-1" and observe.reached
    unseen = answers["Visit hood-1 in Level-0 of car-2"]
    assert not unseen.reached and "unknown feature 'hood-1'" in unseen.error
    plan = HierarchicalPlanner(small_mission.graph).query("Visit car-2")
    assert plan.target_route[-1] == "car-2"


def test_the_same_seed_gives_the_same_mission(small_mission, mission_queries, tmp_path) -> None:
    config = make_config({"world": "campus", "scenario": "small", "seed": 0})
    again = run_mission(config, tmp_path / "again", queries=mission_queries)
    first = (small_mission.run_dir / "graph.json").read_text()
    assert (again.run_dir / "graph.json").read_text() == first
    assert again.metrics.mission.sim_time_s == small_mission.metrics.mission.sim_time_s


def test_an_interrupted_run_leaves_a_valid_run_directory(tmp_path: Path) -> None:
    calls = {"n": 0}

    def interrupt_midway(progress) -> None:
        calls["n"] += 1
        if progress.phase == "inspect" and progress.inspected >= 1:
            raise KeyboardInterrupt

    config = make_config({"world": "campus", "scenario": "small", "seed": 1})
    result = run_mission(config, tmp_path / "run", progress=interrupt_midway)
    assert result.state == "interrupted" and "Ctrl-C" in result.reason
    status = read_versioned_json(tmp_path / "run" / "status.json", "seminspect.run-status", [1])
    assert status["state"] == "interrupted"
    graph = load_graph(tmp_path / "run" / "graph.json")
    assert graph.population().targets_inspected >= 1
    assert (tmp_path / "run" / "metrics.json").exists()
    assert not list((tmp_path / "run").glob(".*.tmp"))  # no half-written file left behind


def test_a_failure_mid_mission_is_recorded_and_reported(tmp_path: Path, monkeypatch) -> None:
    def broken(self, target) -> None:
        raise RuntimeError("camera unplugged")

    monkeypatch.setattr(XFlie, "inspect", broken)
    config = make_config({"world": "campus", "scenario": "small", "seed": 0})
    with pytest.raises(SeminspectError, match="camera unplugged"):
        run_mission(config, tmp_path / "run")
    status = read_versioned_json(tmp_path / "run" / "status.json", "seminspect.run-status", [1])
    assert status["state"] == "failed" and "camera unplugged" in status["reason"]
    assert load_graph(tmp_path / "run" / "graph.json").targets()  # what was found survives


def test_every_edge_of_the_graph_is_traversable_in_the_world(small_mission) -> None:
    graph, world = small_mission.graph, small_mission.world
    radius = small_mission.config.robot.radius
    spatial = [e for e in graph.edges() if e.kind is EdgeKind.SPATIAL]
    assert len(spatial) > 40
    for edge in spatial:
        path = graph.edge_path(edge)
        for a, b in pairwise(path):
            assert world.segment_is_free(a, b, radius, "ground"), (edge.u, edge.v)


def test_the_run_keeps_the_robots_final_map(small_mission_dir: Path) -> None:
    saved = load_map(small_mission_dir / "map.npz")
    assert saved.counts()["occupied"] > 0
    final = load_trajectory(small_mission_dir)[-1, 5:8]
    assert saved.states[tuple(saved.world_to_index(final))] == FREE  # where the robot stands


def test_the_volumetric_baseline_mission_plans_with_charged_time(tmp_path: Path) -> None:
    config = make_config(
        {"world": "subterranean", "scenario": None, "planner": "volumetric"}
        | {"charge_planning_time": True}
    )
    result = run_mission(config, tmp_path / "baseline")
    mission, metrics = result.mission, result.metrics
    assert result.state == "completed" and metrics.targets.inspected >= 1
    assert mission.volumetric is not None and not mission.recorder.plans  # no graph legs
    assert metrics.mission.planning_time_charged
    planning = metrics.mission.planning_wall_s
    assert planning > 0
    assert metrics.table6.planning_load_pct == pytest.approx(
        100 * planning / metrics.mission.sim_time_s
    )


def test_a_ctrl_c_while_writing_outputs_is_not_reported_as_completed(tmp_path, monkeypatch) -> None:
    def interrupted_write(path, occupancy) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(outputs, "save_map", interrupted_write)
    config = make_config({"world": "subterranean", "time_budget_s": 10})
    result = run_mission(config, tmp_path / "run")
    status = read_versioned_json(tmp_path / "run" / "status.json", "seminspect.run-status", [1])
    assert result.state == status["state"] == "interrupted"
    assert "while writing the outputs" in status["reason"]
    for missing in ("map.npz", "metrics.json"):
        assert missing in status["reason"] and not (tmp_path / "run" / missing).exists()
    assert load_graph(tmp_path / "run" / "graph.json") is not None  # written before the maps


def test_a_bad_world_creates_no_run_directory(tmp_path) -> None:
    config = make_config({"world": "campus", "scenario": "huge"})
    with pytest.raises(SeminspectError, match="unknown campus scenario"):
        run_mission(config, base=tmp_path)
    assert not list(tmp_path.iterdir())
