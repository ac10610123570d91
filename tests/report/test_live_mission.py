"""The live view of a mission: its messages say what the mission holds, and in a real browser
the page fills and updates while a mission runs and ends with the mission's final graph."""

from __future__ import annotations

import base64
import json
import threading
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest

from seminspect.graphs.lsg.io import load_graph
from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.live import LiveWatch
from seminspect.missions.xflie.run import run_mission
from seminspect.report.browser import find_chromium, open_page
from seminspect.report.live_mission import (
    MAX_MAP_POINTS,
    TRACES,
    MissionFeed,
    camera_picture,
    graph_traces,
    live_page,
    occupied_points,
)
from seminspect.report.live_server import LiveServer
from seminspect.sensors import CameraModel, Detection, Frame

LAYERS = ("Feature", "Pose", "Level", "Target")


class _Server:
    """What a feed needs of a server, keeping what was sent."""

    def __init__(self) -> None:
        self.scene: dict | None = None
        self.sent: list[dict] = []
        self.maps: list[dict] = []

    def ready(self) -> bool:
        return True

    def set_scene(self, scene: dict) -> None:
        self.scene = scene

    def send(self, message: dict, event: str = "message") -> None:
        kept = self.sent if event == "message" else self.maps
        kept.append(json.loads(json.dumps(message, allow_nan=False)))


def _frame(intensity: bool) -> Frame:
    camera = CameraModel(width=64, height=48)
    shape = (camera.height, camera.width)
    depth = np.full(shape, np.inf, np.float32)
    depth[10:30, 20:40] = 5.0
    return Frame(
        depth=depth,
        instance=np.zeros(shape, np.int32),
        class_id=np.zeros(shape, np.int16),
        part_id=np.zeros(shape, np.int16),
        intensity=np.full(shape, 128, np.uint8) if intensity else None,
        face=np.full(shape, -1, np.int32),
        position=(0.0, 0.0, 1.0),
        orientation=(1.0, 0.0, 0.0, 0.0),
        stamp=0.0,
        camera=camera,
    )


def _box(shape: tuple[int, int]) -> Detection:
    mask = np.zeros(shape, bool)
    mask[10:30, 20:40] = True
    return Detection("car", mask, int(mask.sum()), 0.9, (20, 10, 40, 30), 1, "instance", 5.0)


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
    # the box's outline (20..40 x 10..30 px of 64 x 48, scaled by 7.5) and its caption
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
    assert set(traces) | {"world", "map", "path", "robot"} == set(TRACES)


@pytest.fixture(scope="module")
def feed_messages(tmp_path_factory: pytest.TempPathFactory) -> tuple[_Server, Path]:
    server = _Server()
    out = tmp_path_factory.mktemp("live") / "run"
    config = make_config({"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 120})
    run_mission(config, out, watch=LiveWatch(MissionFeed(server)))  # type: ignore[arg-type]
    return server, out


def test_messages_are_the_mission_as_it_stood(feed_messages) -> None:
    server, out = feed_messages
    assert server.scene is not None and len(server.scene["world"]["x"]) > 10
    first, last = server.sent[0], server.sent[-1]
    assert first["t"] < last["t"] and first["final"] is None
    assert last["final"] == "completed"
    assert last["pose"][:3] == pytest.approx(
        [last["traces"]["path"][axis][-1] for axis in "xyz"], abs=0.01
    )
    graph = load_graph(out / "graph.json")
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    assert {layer: len(last["traces"][layer]["x"]) for layer in LAYERS} == {
        layer: counts[layer] for layer in LAYERS
    }
    # the map goes on its own, at most every MAP_PERIOD_S, and once more at the end
    assert 1 < len(server.maps) < len(server.sent) / 2
    assert 0 < len(server.maps[-1]["x"]) <= MAX_MAP_POINTS
    assert any(m["detections"] for m in server.sent)
    assert all(m["image"] is None or m["image"].startswith("data:image/jpeg") for m in server.sent)
    assert any(m["target"] is not None for m in server.sent)


def _drawn(page) -> dict[str, int]:
    """Points plotly drew in each trace of the live scene."""
    return page.evaluate(
        "() => Object.fromEntries(document.getElementById('live-scene')._fullData"
        ".map((t) => [t.meta.trace, t._length ?? 0]))"
    )


@pytest.mark.slow
def test_the_live_view_updates_in_a_browser(tmp_path: Path) -> None:
    if find_chromium() is None:
        pytest.skip("no Chromium found (apt-get install chromium, or set $SEMINSPECT_CHROMIUM)")
    pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    config = make_config({"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 200})
    out = tmp_path / "run"
    with LiveServer(live_page("live test"), port=0, period_s=0.2) as server:

        def mission() -> None:
            if server.wait_for_client(60):
                run_mission(config, out, watch=LiveWatch(MissionFeed(server)))

        runner = threading.Thread(target=mission)
        with open_page(server.url) as (page, errors):
            runner.start()
            sim_time = "() => Number(document.body.dataset.simTime ?? -1)"
            page.wait_for_function(f"() => ({sim_time})() > 0", timeout=60_000)
            early_time, early = page.evaluate(sim_time), _drawn(page)
            page.wait_for_function(f"t => ({sim_time})() > t + 20", arg=early_time, timeout=60_000)
            page.wait_for_selector("text=mission completed", timeout=120_000)
            final = _drawn(page)
            camera = page.get_attribute("#camera", "src")
            status = page.inner_text("#status")
            page.screenshot(path=str(tmp_path / "live.png"))
        runner.join(30)
    assert errors == []
    assert early["world"] > 10  # the scene arrived first
    assert final["path"] > early["path"] > 0 and final["map"] > 0
    graph = load_graph(out / "graph.json")
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    assert {layer: final[layer] for layer in LAYERS} == {layer: counts[layer] for layer in LAYERS}
    assert final["Target"] >= early["Target"] and final["Target"] > 0
    assert camera is not None and camera.startswith("data:image/jpeg;base64,")
    assert "pursuing" in status and "completed" in status
    assert (tmp_path / "live.png").stat().st_size > 20_000
