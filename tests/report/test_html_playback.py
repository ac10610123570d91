"""The mission report's playback: what the slider shows at a time, and the figure it slices."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import PoseNode, RobotNode, TargetNode
from seminspect.missions.xflie.layout import load_run_world
from seminspect.report.html_mission import footprint_trace
from seminspect.report.html_page import thumbnails
from seminspect.report.html_playback import (
    Playback,
    mission_playback,
    playback_figure,
    playback_section,
)
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_trajectory


def _playback() -> Playback:
    trajectory = np.array(
        [[0.0, 0.0, 0.0, 0.5, 0.0], [1.0, 1.0, 0.0, 0.5, 0.1], [3.0, 2.0, 1.0, 0.5, 0.2]]
    )
    views = ((1.5, "images/a.jpg"), (2.5, "images/b.jpg"))
    return Playback(4.0, {"t": 0.5, "p1": 1.5, "p2": 2.5, "f": 4.0}, views, trajectory)


def test_nodes_stand_from_the_time_they_entered_the_graph() -> None:
    playback = _playback()
    assert playback.nodes_at(0.0) == set()
    assert playback.nodes_at(1.5) == {"t", "p1"}  # a node entering at t is there at t
    assert playback.nodes_at(2.4) == {"t", "p1"}
    assert playback.nodes_at(4.0) == {"t", "p1", "p2", "f"}


def test_the_pose_is_the_last_trajectory_row_at_or_before_the_time() -> None:
    playback = _playback()
    assert playback.pose_at(-1.0) == pytest.approx([0.0, 0.0, 0.5, 0.0])  # before: the start
    assert playback.pose_at(1.0) == pytest.approx([1.0, 0.0, 0.5, 0.1])
    assert playback.pose_at(2.9) == pytest.approx([1.0, 0.0, 0.5, 0.1])
    assert playback.pose_at(10.0) == pytest.approx([2.0, 1.0, 0.5, 0.2])
    empty = Playback(1.0, {}, (), np.empty((0, 5)))
    assert empty.pose_at(0.5) is None


def test_the_view_is_the_latest_one_taken() -> None:
    playback = _playback()
    assert playback.view_at(1.4) is None
    assert playback.view_at(1.5) == "images/a.jpg"
    assert playback.view_at(2.0) == "images/a.jpg"
    assert playback.view_at(9.0) == "images/b.jpg"


@pytest.fixture(scope="module")
def footprints(small_mission_dir: Path):
    return footprint_trace(load_run_world(small_mission_dir))


@pytest.fixture(scope="module")
def mission(small_mission_dir: Path):
    graph = load_graph(small_mission_dir / "graph.json")
    images = thumbnails(
        small_mission_dir, {n.image for n in graph.nodes() if getattr(n, "image", None)}
    )
    events = load_events(small_mission_dir)
    trajectory = load_trajectory(small_mission_dir)
    return graph, events, trajectory, images


def test_the_small_mission_plays_back_as_its_log_says(mission) -> None:
    graph, events, trajectory, images = mission
    playback = mission_playback(graph, events, trajectory, images)
    assert playback.end_s == pytest.approx(trajectory[-1, 0])
    nodes = {n.id for n in graph.nodes() if not isinstance(n, RobotNode)}
    assert playback.nodes_at(playback.end_s) == nodes
    assert playback.nodes_at(0.0) == set()
    detected = next(e for e in events if e["event"] == "detected")
    just_before = playback.nodes_at(detected["t"] - 1e-6)
    assert detected["target"] not in just_before
    assert detected["target"] in playback.nodes_at(detected["t"])
    poses = [n for n in graph.nodes() if isinstance(n, PoseNode)]
    middle = playback.end_s / 2
    standing = playback.nodes_at(middle) & {n.id for n in poses}
    assert standing == {n.id for n in poses if n.stamp <= middle} and 0 < len(standing) < len(poses)
    latest = max((n for n in poses if n.stamp <= middle), key=lambda n: n.stamp)
    assert playback.view_at(middle) == latest.image and latest.image in images
    pose = playback.pose_at(middle)
    assert pose is not None and not np.allclose(pose, playback.pose_at(playback.end_s))


def test_a_view_whose_image_is_missing_is_not_shown(mission) -> None:
    graph, events, trajectory, _ = mission
    playback = mission_playback(graph, events, trajectory, {})
    assert playback.views == () and playback.view_at(playback.end_s) is None


def test_a_run_without_trajectory_or_log_ends_at_its_last_view(mission) -> None:
    graph, _, _, images = mission
    playback = mission_playback(graph, [], np.empty((0, 9)), images)
    stamps = [n.stamp for n in graph.nodes() if isinstance(n, PoseNode)]
    assert playback.end_s == pytest.approx(max(stamps)) and playback.pose_at(1.0) is None
    targets = {n.id for n in graph.nodes() if isinstance(n, TargetNode)}
    assert targets <= playback.nodes_at(playback.end_s)  # unknown times: at the end


def test_every_timed_trace_is_in_time_order_and_holds_the_final_graph(mission, footprints) -> None:
    graph, events, trajectory, images = mission
    playback = mission_playback(graph, events, trajectory, images)
    figure = playback_figure(playback, graph, footprints)
    kinds = {trace.meta["playback"]: trace for trace in figure.data if trace.meta}
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    for layer in ("Feature", "Pose", "Level", "Target"):
        assert len(kinds[layer].x) == counts[layer]
    for kind in ("trajectory", "spatial edges", "symbolic edges", *counts):
        times = [c[0] if isinstance(c, list | tuple) else c for c in kinds[kind].customdata]
        assert times == sorted(times), kind
        assert len(times) == len(kinds[kind].x)
    # no frames: the page slices what the figure holds rather than repeat it per step
    assert not figure.frames
    assert kinds["robot"].x[0] == pytest.approx(trajectory[-1, 1], abs=1e-3)


def test_the_section_carries_the_slider_and_its_views(mission, footprints) -> None:
    graph, events, trajectory, images = mission
    playback = mission_playback(graph, events, trajectory, images)
    section = playback_section(playback, graph, footprints)
    assert section is not None
    body = section.body
    assert 'id="playback-time"' in body and 'id="playback-play"' in body
    assert "latest inspection view" in body
    data = body.split('id="playback-data">', 1)[1].split("</script>", 1)[0]
    views = json.loads(data)["views"]
    assert [image for _, image in views] == [image for _, image in playback.views]
    maximum = float(body.split('max="', 1)[1].split('"', 1)[0])
    assert playback.end_s <= maximum < playback.end_s + 0.1 + 1e-9  # its end shows everything
    nothing = Playback(0.0, {}, (), np.empty((0, 5)))  # a run that never moved the clock
    assert playback_section(nothing, graph, footprints) is None
