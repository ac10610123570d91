"""A run recorded as MCAP: standard ROS 2 channels in time order, holding what the run holds."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import wrap_angle
from seminspect.graphs.lsg.io import load_graph
from seminspect.mapping.formats.rosbag import read_bag_scans, ros_typestore
from seminspect.missions.xflie import recording
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.layout import read_metrics_document
from seminspect.missions.xflie.lsg_markers import node_times
from seminspect.missions.xflie.recording import RecordingRates, record_run
from seminspect.missions.xflie.replay import sampled_rows
from seminspect.missions.xflie.run import run_mission
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_trajectory

pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")
mcap_reader = pytest.importorskip("mcap.reader", reason="the test extra (mcap) is not installed")

#: Sparse sensor channels keep the test quick; the defaults are measured in docs/missions.md.
RATES = RecordingRates(scan_period_s=10.0, image_period_s=5.0, graph_period_s=1.0)
SCHEMAS = {
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/odom": "nav_msgs/msg/Odometry",
    "/points": "sensor_msgs/msg/PointCloud2",
    "/camera/image/compressed": "sensor_msgs/msg/CompressedImage",
    "/camera/camera_info": "sensor_msgs/msg/CameraInfo",
    "/seminspect/lsg": "visualization_msgs/msg/MarkerArray",
    "/seminspect/events": "std_msgs/msg/String",
    "/seminspect/label_names": "std_msgs/msg/String",
}


@pytest.fixture(scope="module")
def tunnel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tunnel's one-car mission (the quickest that inspects), recorded."""
    run_dir = tmp_path_factory.mktemp("recording") / "tunnel"
    run_mission(make_config({"world": "subterranean"}), run_dir)
    assert record_run(run_dir, rates=RATES) == run_dir / "run.mcap"
    return run_dir


def _mcap_messages(path: Path) -> list[tuple[str, str, int]]:
    """``(topic, schema, log time)`` of every message, in file order."""
    with path.open("rb") as stream:
        reader = mcap_reader.make_reader(stream)
        return [
            (channel.topic, schema.name, message.log_time)
            for schema, channel, message in reader.iter_messages(log_time_order=False)
        ]


def test_every_channel_is_a_standard_type_in_time_order(tunnel: Path) -> None:
    messages = _mcap_messages(tunnel / "run.mcap")
    assert {topic: schema for topic, schema, _ in messages} == SCHEMAS
    trajectory = load_trajectory(tunnel)
    counts = Counter(topic for topic, _, _ in messages)
    assert counts["/tf"] == counts["/odom"] == len(trajectory)
    assert counts["/points"] == len(sampled_rows(trajectory, RATES.scan_period_s))
    images = len(sampled_rows(trajectory, RATES.image_period_s))
    assert counts["/camera/image/compressed"] == counts["/camera/camera_info"] == images
    assert counts["/seminspect/events"] == len(load_events(tunnel))
    assert counts["/tf_static"] == counts["/seminspect/label_names"] == 1
    assert 1 < counts["/seminspect/lsg"] < len(trajectory)
    times = np.array([log_time for _, _, log_time in messages])
    assert np.all(np.diff(times) >= 0)
    sim_time_ns = read_metrics_document(tunnel)["mission"]["sim_time_s"] * 1e9
    assert times[0] >= 0 and times[-1] <= sim_time_ns + 1e6  # events.jsonl rounds to ms


def _decoded(path: Path, topic: str) -> list:
    from rosbags.highlevel import AnyReader

    with AnyReader([path], default_typestore=ros_typestore()) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return [
            reader.deserialize(raw, connection.msgtype)
            for connection, _, raw in reader.messages(connections=connections)
        ]


def test_the_poses_are_the_trajectorys(tunnel: Path) -> None:
    trajectory = load_trajectory(tunnel)
    tf = _decoded(tunnel / "run.mcap", "/tf")
    for row, message in zip(trajectory, tf, strict=True):
        true, believed = message.transforms
        assert (true.header.frame_id, true.child_frame_id) == ("map", "base_link")
        t = true.transform.translation
        np.testing.assert_allclose([t.x, t.y, t.z], row[1:4])
        q = true.transform.rotation
        assert abs(wrap_angle(2 * np.arctan2(q.z, q.w) - row[4])) < 1e-9 and q.x == q.y == 0
        b = believed.transform.translation
        np.testing.assert_allclose([b.x, b.y, b.z], row[5:8])
    # the clouds read back as 'seminspect terrain map --bag' reads them: posed by odometry
    scans = list(read_bag_scans(tunnel / "run.mcap", "/points", "/odom", labels_field="label"))
    assert scans and all(len(scan.points) == len(scan.labels) > 0 for scan in scans)


def test_the_camera_and_the_graph_are_there_to_see(tunnel: Path) -> None:
    image = _decoded(tunnel / "run.mcap", "/camera/image/compressed")[0]
    info = _decoded(tunnel / "run.mcap", "/camera/camera_info")[0]
    grey = cv2.imdecode(np.asarray(image.data, np.uint8), cv2.IMREAD_UNCHANGED)
    assert grey.shape == (info.height, info.width) and image.format == "jpeg"
    final = _decoded(tunnel / "run.mcap", "/seminspect/lsg")[-1].markers
    graph = load_graph(tunnel / "graph.json")
    names = {m.text for m in final if m.ns.endswith(" names")}
    assert names == {node.name for node in graph.nodes() if node.id != "robot"}
    assert final[0].action == 3  # DELETEALL: every message holds the whole graph so far
    assert {m.ns for m in final} >= {"target", "level", "pose", "feature", "spatial edges"}


def test_nodes_appear_when_the_events_say_they_were_added(tunnel: Path) -> None:
    graph, events = load_graph(tunnel / "graph.json"), load_events(tunnel)
    end = float(load_trajectory(tunnel)[-1, 0])
    times = node_times(graph, events, end)
    detected = next(e["t"] for e in events if e["event"] == "detected")
    completed = next(e["t"] for e in events if e["event"] == "level-complete")
    target = graph.targets()[0]
    level = target.levels[0]
    feature = next(f for pose in level.poses for f in pose.features)
    assert times[target.id] == detected and times[feature.id] == completed
    assert times[level.id] == level.stamp < times[level.poses[-1].id] < completed + 1e-3  # ms
    assert node_times(graph, [], end)[target.id] == end  # no log: at the end


def test_a_failed_recording_leaves_no_file(tunnel: Path, monkeypatch, tmp_path: Path) -> None:
    renders = {"n": 0}
    real_render = recording.render

    def render_twice(*args, **kwargs):
        renders["n"] += 1
        if renders["n"] > 2:
            raise InvalidInputError("camera unplugged")
        return real_render(*args, **kwargs)

    monkeypatch.setattr(recording, "render", render_twice)
    with pytest.raises(InvalidInputError, match="camera unplugged"):
        record_run(tunnel, tmp_path / "run.mcap", rates=RATES)
    assert list(tmp_path.iterdir()) == []
