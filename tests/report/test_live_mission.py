"""The live view of a mission: its messages say what the mission holds, and in a real browser
the page fills and updates while a mission runs and ends with the mission's final graph."""

from __future__ import annotations

import base64
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest

from live_pages import RecordingServer, grew, watch_in_browser
from seminspect.graphs.lsg.io import load_graph
from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.live import LiveWatch
from seminspect.missions.xflie.run import run_mission
from seminspect.report.live_common import MAX_MAP_POINTS, camera_picture, occupied_points
from seminspect.report.live_mission import LAYERS as LAYER_TRACES
from seminspect.report.live_mission import MissionFeed, graph_traces, live_page
from seminspect.report.live_server import LiveServer
from seminspect.sensors import CameraModel, Detection, Frame

LAYERS = ("Feature", "Pose", "Level", "Target")
assert LAYER_TRACES == LAYERS  # the page's trace names are the layers' own


def _frame(intensity: bool) -> Frame:
    camera = CameraModel(width=320, height=240)
    shape = (camera.height, camera.width)
    depth = np.full(shape, np.inf, np.float32)
    depth[50:150, 100:200] = 5.0
    return Frame(
        depth=depth,
        instance=np.zeros(shape, np.int32),
        class_id=np.zeros(shape, np.int16),
        part_id=np.zeros(shape, np.int16),
        intensity=np.full(shape, 128, np.uint8) if intensity else None,
        face=np.full(shape, -1, np.int32),
        position=(0.0, 0.0, 1.0),
        orientation=(0.0, 0.0, 0.0, 1.0),
        stamp=0.0,
        camera=camera,
    )


def _box(shape: tuple[int, int]) -> Detection:
    mask = np.zeros(shape, bool)
    mask[50:150, 100:200] = True
    return Detection("car", mask, int(mask.sum()), 0.9, (100, 50, 200, 150), 1, "instance", 5.0)


def _decoded(uri: str) -> np.ndarray:
    assert uri.startswith("data:image/jpeg;base64,")
    data = np.frombuffer(base64.b64decode(uri.split(",", 1)[1]), np.uint8)
    return cv2.imdecode(data, cv2.IMREAD_COLOR)


@pytest.mark.parametrize("intensity", [True, False])
def test_the_camera_picture_shows_the_frame_with_its_boxes(intensity: bool) -> None:
    frame = _frame(intensity)
    plain = _decoded(camera_picture(frame, []))
    boxed = _decoded(camera_picture(frame, [_box(frame.shape)]))
    assert plain.shape == (360, 480, 3)  # scaled to the page's width
    changed = np.abs(boxed.astype(int) - plain.astype(int)).max(axis=2) > 60
    rows, cols = np.nonzero(changed)
    # the box's outline (100..200 x 50..150 px of 320 x 240, scaled by 1.5) and its caption
    assert cols.min() >= 140 and cols.max() <= 310 and rows.max() <= 230
    assert changed[75:225, 148:152].mean() > 0.5  # its left edge


def test_a_frame_without_its_image_shows_its_depth() -> None:
    picture = _decoded(camera_picture(_frame(intensity=False), []))
    assert picture[150, 225].mean() > picture[20, 20].mean() + 50  # near is bright, nothing dark


def test_the_map_is_its_occupied_voxels_subsampled() -> None:
    states = np.zeros((100, 100, 10), np.uint8)
    states[:, :, 0] = OCCUPIED  # 10,000 occupied cells
    occupancy = VoxelMap((0.0, 0.0, 0.0), 0.5, states)
    points = occupied_points(occupancy)
    assert MAX_MAP_POINTS / 2 <= len(points) <= MAX_MAP_POINTS
    assert np.allclose(points[:, 2], 0.25)  # cell centres
    states[:] = 0
    states[3, 4, 5] = OCCUPIED
    assert occupied_points(VoxelMap((0.0, 0.0, 0.0), 0.5, states)).tolist() == [[1.75, 2.25, 2.75]]


def test_graph_traces_hold_every_node_and_edge(small_mission_dir: Path) -> None:
    graph = load_graph(small_mission_dir / "graph.json")
    traces = graph_traces(graph)
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    assert {layer: len(traces[layer]["x"]) for layer in LAYERS} == {
        layer: counts[layer] for layer in LAYERS
    }
    assert all(len(traces[layer]["text"]) == counts[layer] for layer in LAYERS)
    edges = len(traces["spatial edges"]["x"]) + len(traces["symbolic edges"]["x"])
    assert edges == 3 * sum(1 for _ in graph.edges())
    assert all(traces[layer]["name"] == f"{layer} ({counts[layer]})" for layer in LAYERS)
    assert set(traces) == {*LAYERS, "spatial edges", "symbolic edges"}


@pytest.fixture(scope="module")
def feed_messages(tmp_path_factory: pytest.TempPathFactory) -> tuple[RecordingServer, Path]:
    server = RecordingServer()
    out = tmp_path_factory.mktemp("live") / "run"
    config = make_config({"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 120})
    run_mission(config, out, watch=LiveWatch(MissionFeed(server)))  # type: ignore[arg-type]
    return server, out


def test_messages_are_the_mission_as_it_stood(feed_messages) -> None:
    server, out = feed_messages
    assert server.scene is not None and len(server.scene["traces"]["world"]["x"]) > 10
    first, last = server.sent[0], server.sent[-1]
    assert first["t"] < last["t"] and first["final"] is None
    assert last["final"] == "mission completed"
    assert dict(map(tuple, last["status"]))["mission"] == "completed"
    assert last["pose"][:3] == pytest.approx(
        [last["traces"]["path"][axis][-1] for axis in "xyz"], abs=0.01
    )
    graph = load_graph(out / "graph.json")
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    assert {layer: len(last["traces"][layer]["x"]) for layer in LAYERS} == {
        layer: counts[layer] for layer in LAYERS
    }
    # the map goes on its own, at most every MAP_PERIOD_S, and once more at the end
    assert set(server.events) == {"traces"}
    assert 1 < len(server.events["traces"]) < len(server.sent) / 2
    assert 0 < len(server.events["traces"][-1]["traces"]["map"]["x"]) <= MAX_MAP_POINTS
    with_detections = [m for m in server.sent if m["detections"]]
    assert with_detections and all(
        m["detections"][0]["label"] in m["caption"] for m in with_detections
    )
    assert all(m["image"] is None or m["image"].startswith("data:image/jpeg") for m in server.sent)
    assert any(dict(map(tuple, m["status"]))["pursuing"] != "-" for m in server.sent)


@pytest.mark.slow
def test_the_live_view_updates_in_a_browser(tmp_path: Path) -> None:
    config = make_config({"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 200})
    out = tmp_path / "run"

    def mission(server: LiveServer) -> None:
        run_mission(config, out, watch=LiveWatch(MissionFeed(server)))

    page = live_page("live test")
    seen = watch_in_browser(page, mission, "mission completed", tmp_path / "live.png")
    final = seen.final
    assert seen.errors == []
    assert final["world"] > 10 and final["map"] > 0
    assert grew(seen.states) and seen.states[-1][1] == final["path"]
    graph = load_graph(out / "graph.json")
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    assert {layer: final[layer] for layer in LAYERS} == {layer: counts[layer] for layer in LAYERS}
    assert final["Target"] > 0
    assert seen.camera is not None and seen.camera.startswith("data:image/jpeg;base64,")
    assert "pursuing" in seen.status and "completed" in seen.status
    assert (tmp_path / "live.png").stat().st_size > 20_000
