"""A small two-robot mission end to end: the shared graph's invariants and the run directory."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import LevelNode, PoseNode, TargetStatus
from seminspect.missions.xflie.config import make_config, resolve
from seminspect.missions.xflie.layout import read_metrics_document
from seminspect.missions.xflie.run import run_mission
from seminspect.missions.xflie.team_run import build_team
from seminspect.report.run_pictures import render_run
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_robot_trajectories
from seminspect.worlds import open_world

TEAM = {"world": "campus", "scenario": "small", "seed": 0, "robots": ["explorer", "inspector"]}


@pytest.fixture(scope="module")
def team_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("team") / "campus-small-team"
    result = run_mission(make_config(TEAM), out)
    assert result.state == "completed", result.reason
    return out


def test_both_robots_share_one_graph_and_one_map_but_not_a_body() -> None:
    config = resolve(make_config(TEAM))
    team = build_team(config, open_world(config.world, config.scenario, seed=config.seed), None)
    explorer, inspector = team.explorer.mission, team.inspector.mission
    assert explorer.graph is inspector.graph
    assert explorer.occupancy is inspector.occupancy
    assert explorer.platform is not inspector.platform
    assert explorer.navigator is not inspector.navigator


@pytest.mark.slow
def test_the_shared_graph_holds_no_duplicate_targets(team_run: Path) -> None:
    graph = load_graph(team_run / "graph.json")
    metrics = read_metrics_document(team_run)
    targets = graph.targets()
    assert targets and metrics["targets"]["false_targets"] == 0
    truths = [m["truth"] for m in metrics["targets"]["matches"]]
    assert len(truths) == len(set(truths)) == len(targets)
    d_check = graph.params.d_check_T
    for a, b in itertools.combinations(targets, 2):
        if a.label == b.label:
            assert np.linalg.norm((a.position - b.position)[:2]) > d_check


@pytest.mark.slow
def test_every_target_is_inspected_exactly_once_by_one_robot(team_run: Path) -> None:
    graph = load_graph(team_run / "graph.json")
    robots = read_metrics_document(team_run)["robots"]
    inspected = {t.id for t in graph.targets(TargetStatus.INSPECTED)}
    assert inspected == {t.id for t in graph.targets()}
    by_robot = robots["explorer"]["inspected"] + robots["inspector"]["inspected"]
    assert sorted(by_robot) == sorted(inspected)  # each once, by one of the two
    events = load_events(team_run)
    ends = [e["target"] for e in events if e["event"] == "inspected"]
    assert sorted(ends) == sorted(inspected)


@pytest.mark.slow
def test_claims_never_overlap_and_both_robots_take_targets(team_run: Path) -> None:
    steps = [e for e in load_events(team_run) if e["event"] == "activity"]
    pursuits: dict[str, list[tuple[float, float, str]]] = {}
    for s in steps:
        if "target" in s:  # a pursuit: the claim's interval on its robot's clock
            pursuits.setdefault(s["target"], []).append((s["start"], s["end"], s["robot"]))
    assert pursuits
    for target, claims in pursuits.items():
        claims.sort()
        for (_, end, _), (start, _, _) in itertools.pairwise(claims):
            assert start >= end, target
    assert {robot for claims in pursuits.values() for _, _, robot in claims} == {
        "explorer",
        "inspector",
    }


@pytest.mark.slow
def test_every_level_and_pose_belongs_to_a_target(team_run: Path) -> None:
    graph = load_graph(team_run / "graph.json")
    levels = {id(level) for t in graph.targets() for level in t.levels}
    poses = {id(pose) for t in graph.targets() for level in t.levels for pose in level.poses}
    nodes = list(graph.nodes())
    assert any(isinstance(n, PoseNode) for n in nodes)
    for node in nodes:
        if isinstance(node, LevelNode):
            assert id(node) in levels, node.id
        if isinstance(node, PoseNode):
            assert id(node) in poses, node.id


@pytest.mark.slow
def test_both_robots_moved_and_each_has_its_trajectory_and_timeline(team_run: Path) -> None:
    trajectories = load_robot_trajectories(team_run)
    assert set(trajectories) == {"explorer", "inspector"}
    robots = read_metrics_document(team_run)["robots"]
    for name, path in trajectories.items():
        assert robots[name]["mission"]["distance_m"] > 1.0
        assert np.ptp(path[:, 1:3], axis=0).max() > 1.0
    steps = [e for e in load_events(team_run) if e["event"] == "activity"]
    assert {e["robot"] for e in steps} == {"explorer", "inspector"}
    metrics = read_metrics_document(team_run)
    clocks = [r["mission"]["sim_time_s"] for r in robots.values()]
    assert metrics["mission"]["sim_time_s"] == pytest.approx(max(clocks))
    assert "## Robots" in (team_run / "summary.md").read_text(encoding="utf-8")
    pictures = [p.name for p in render_run(team_run)]
    assert pictures == ["trajectory.png", "graph.png", "utility.png", "timeline.png"]


@pytest.mark.slow
def test_a_team_mission_is_deterministic_for_its_seed(tmp_path: Path) -> None:
    short = make_config(TEAM | {"time_budget_s": 120.0})
    runs = [tmp_path / "a", tmp_path / "b"]
    for out in runs:
        run_mission(short, out)
    first, second = (load_robot_trajectories(out) for out in runs)
    for name in first:
        np.testing.assert_array_equal(first[name], second[name])
    graphs = [json.loads((out / "graph.json").read_text(encoding="utf-8")) for out in runs]
    assert graphs[0] == graphs[1]
    assert load_events(runs[0]) == load_events(runs[1])
