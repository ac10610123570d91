"""ROS bags seminspect did not write: made here with ``rosbags`` alone, as a robot records them."""

from __future__ import annotations

import sqlite3
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cli_runner import run
from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.formats import rosbag
from seminspect.mapping.formats.rosbag import read_bag_scans, read_label_names
from seminspect.mapping.formats.semantickitti import label_table
from seminspect.mapping.semantic_cloud import load_cloud

pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")

from rosbags.typesys import Stores, get_typestore

START_NS = 1_700_000_000_000_000_000
STEP_NS = 100_000_000
OUSTER_FIELDS = (("x", 7), ("y", 7), ("z", 7), ("intensity", 7), ("label", 6))


@dataclass
class Recording:
    """What a foreign bag holds: clouds on /ouster/points, odometry on /odom, maybe /tf_static."""

    clouds: int = 3
    cloud_frame: str = "os_sensor"
    odom_frame: str = "odom"
    child_frame: str = "os_sensor"
    fields: tuple[tuple[str, int], ...] = OUSTER_FIELDS
    #: odometry stamps as multiples of STEP_NS from START_NS, with a yaw per message
    odometry: list[tuple[int, float]] = field(
        default_factory=lambda: [(k, 0.1 * k) for k in range(3)]
    )
    #: (parent, child, translation) static transforms
    tf_static: list[tuple[str, str, tuple[float, float, float]]] = field(default_factory=list)
    extra: dict[str, str] = field(default_factory=dict)  # topic -> message type, no messages
    point_step: int | None = None  # a cloud's declared point size, when not its fields' own


def _points(k: int) -> np.ndarray:
    rng = np.random.default_rng(k)
    return rng.uniform(-10, 10, (200, 3)).astype(np.float32)


def _time(types, stamp_ns: int):
    return types["builtin_interfaces/msg/Time"](
        sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000
    )


def _header(types, stamp_ns: int, frame: str, ros1: bool):
    extra = {"seq": 0} if ros1 else {}
    return types["std_msgs/msg/Header"](**extra, stamp=_time(types, stamp_ns), frame_id=frame)


def _cloud(types, recording: Recording, k: int, ros1: bool):
    points = _points(k)
    dtype = np.dtype([(name, "<u4" if kind == 6 else "<f4") for name, kind in recording.fields])
    rows = np.zeros(len(points), dtype)
    for axis, name in enumerate("xyz"):
        if name in dtype.names:
            rows[name] = points[:, axis]
    if "label" in dtype.names:
        rows["label"] = np.array([40, 44, 48])[np.arange(len(points)) % 3] | (7 << 16)
    field_type = types["sensor_msgs/msg/PointField"]
    fields = [
        field_type(name=name, offset=dtype.fields[name][1], datatype=kind, count=1)
        for name, kind in recording.fields
    ]
    header = _header(types, START_NS + k * STEP_NS, recording.cloud_frame, ros1)
    return types["sensor_msgs/msg/PointCloud2"](
        header=header, height=1, width=len(rows), fields=fields, is_bigendian=False,
        point_step=recording.point_step or dtype.itemsize, row_step=dtype.itemsize * len(rows),
        data=rows.view(np.uint8).reshape(-1), is_dense=True,
    )  # fmt: skip


def _odometry(types, recording: Recording, step: int, yaw: float, ros1: bool):
    x, y, z, w = Rotation.from_euler("z", yaw).as_quat()
    pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=float(step), y=0.0, z=0.0),
        orientation=types["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
    )
    zero = types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    covariance = np.zeros(36)
    return types["nav_msgs/msg/Odometry"](
        header=_header(types, START_NS + step * STEP_NS, recording.odom_frame, ros1),
        child_frame_id=recording.child_frame,
        pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=covariance),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](
            twist=types["geometry_msgs/msg/Twist"](linear=zero, angular=zero),
            covariance=covariance,
        ),
    )


def _tf_static(types, recording: Recording):
    transforms = [
        types["geometry_msgs/msg/TransformStamped"](
            header=_header(types, START_NS, parent, False),
            child_frame_id=child,
            transform=types["geometry_msgs/msg/Transform"](
                translation=types["geometry_msgs/msg/Vector3"](*offset),
                rotation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        for parent, child, offset in recording.tf_static
    ]
    return types["tf2_msgs/msg/TFMessage"](transforms=transforms)


def record(path: Path, recording: Recording, ros1: bool = False) -> Path:
    """Write ``recording`` as a ROS 2 bag directory, or a ROS 1 ``.bag`` file."""
    if ros1:
        from rosbags.rosbag1 import Writer as Writer1

        store, bag_writer = get_typestore(Stores.ROS1_NOETIC), Writer1(path)
        serialize = store.serialize_ros1
    else:
        from rosbags.rosbag2 import Writer as Writer2

        store, bag_writer = get_typestore(Stores.ROS2_HUMBLE), Writer2(path, version=9)
        serialize = store.serialize_cdr
    types = store.types
    with bag_writer as writer:

        def topic(name: str, msgtype: str):
            return writer.add_connection(name, msgtype, typestore=store)

        odom = topic("/odom", "nav_msgs/msg/Odometry")
        clouds = topic("/ouster/points", "sensor_msgs/msg/PointCloud2")
        for name, msgtype in recording.extra.items():
            topic(name, msgtype)
        if recording.tf_static:
            message = _tf_static(types, recording)
            writer.write(topic("/tf_static", "tf2_msgs/msg/TFMessage"), START_NS,
                         serialize(message, "tf2_msgs/msg/TFMessage"))  # fmt: skip
        for step, yaw in recording.odometry:
            message = _odometry(types, recording, step, yaw, ros1)
            writer.write(
                odom, START_NS + step * STEP_NS, serialize(message, "nav_msgs/msg/Odometry")
            )
        for k in range(recording.clouds):
            message = _cloud(types, recording, k, ros1)
            writer.write(clouds, START_NS + k * STEP_NS,
                         serialize(message, "sensor_msgs/msg/PointCloud2"))  # fmt: skip
    return path


def _map(capsys, bag: Path, out: Path, *extra: str, names: bool = True) -> tuple[int, str, str]:
    """``terrain map --bag``; ``names`` names the labels, so only the fault under test can fail."""
    return run(
        capsys, "terrain", "map", "--bag", str(bag), "--cloud-topic", "/ouster/points",
        "--odom-topic", "/odom", "--encoder", "hashing-test", "--noise", "0", "--out", str(out),
        *(["--label-names", "40=road,44=parking,48=sidewalk"] if names else []), *extra,
    )  # fmt: skip


def _one_error_line(code: int, err: str) -> str:
    assert code == 1 and err.startswith("error:") and len(err.strip().splitlines()) == 1, err
    return err


@pytest.mark.parametrize("ros1", [False, True], ids=["ros2", "ros1"])
def test_a_foreign_bag_maps_with_semantickitti_names(capsys, tmp_path, fake_encoder, ros1):
    bag = record(tmp_path / ("drive.bag" if ros1 else "drive"), Recording(), ros1)
    out = tmp_path / "cloud.npz"
    code, text, err = _map(capsys, bag, out, names=False)
    assert code == 0, err
    assert "warning:" in err and "SemanticKITTI" in err and "/seminspect/label_names" in err
    cloud = load_cloud(out)
    assert f"{len(cloud):,} points" in text and len(cloud) > 300
    scans = list(read_bag_scans(bag, "/ouster/points", "/odom", "label"))
    assert [len(s.points) for s in scans] == [200] * 3
    np.testing.assert_array_equal(scans[1].points, _points(1).astype(np.float64))
    assert set(scans[0].labels.tolist()) == {40, 44, 48}  # instance ids stripped
    np.testing.assert_allclose(scans[2].pose[:3, 3], [2.0, 0.0, 0.0])
    with pytest.warns(rosbag.BagWarning, match="SemanticKITTI"):
        assert read_label_names(bag) == label_table().names


def test_bags_that_are_not_bags_name_what_is_missing(capsys, tmp_path, fake_encoder):
    empty = tmp_path / "empty"
    empty.mkdir()
    err = _one_error_line(*_map(capsys, empty, tmp_path / "a.npz")[::2])
    assert f"{empty}" in err and "empty directory" in err and "metadata.yaml" in err
    bag = record(tmp_path / "drive", Recording())
    (bag / "metadata.yaml").unlink()
    err = _one_error_line(*_map(capsys, bag, tmp_path / "b.npz")[::2])
    assert f"{bag}" in err and "no metadata.yaml" in err and ".db3" in err
    storage = next(bag.glob("*.db3"))  # the file the line names reads as the bag
    assert storage.name in err
    assert len(list(read_bag_scans(storage, "/ouster/points", "/odom", "label"))) == 3


def test_duplicate_odometry_stamps(capsys, tmp_path, fake_encoder):
    twice = Recording(odometry=[(0, 0.0), (1, 0.1), (1, 0.1), (2, 0.2)])
    code, _, err = _map(capsys, record(tmp_path / "twice", twice), tmp_path / "a.npz")
    assert code == 0, err
    clash = Recording(odometry=[(0, 0.0), (1, 0.1), (1, 0.5), (2, 0.2)])
    err = _one_error_line(*_map(capsys, record(tmp_path / "clash", clash), tmp_path / "b.npz")[::2])
    assert "/odom" in err and "1700000000.100" in err and "two different poses" in err


def test_a_cloud_in_another_frame_needs_a_static_transform(capsys, tmp_path, fake_encoder):
    other = Recording(cloud_frame="os_lidar")
    bag = record(tmp_path / "other", other)
    err = _one_error_line(*_map(capsys, bag, tmp_path / "a.npz")[::2])
    assert "'os_lidar'" in err and "'os_sensor'" in err and "/ouster/points" in err
    assert "/tf_static" in err
    chained = Recording(
        cloud_frame="os_lidar",
        child_frame="base_link",
        tf_static=[
            ("base_link", "os_sensor", (1.0, 0.0, 0.0)),
            ("os_sensor", "os_lidar", (0, 0, 2.0)),
        ],
    )
    bag = record(tmp_path / "chained", chained)
    code, _, err = _map(capsys, bag, tmp_path / "b.npz")
    assert code == 0, err
    plain = list(read_bag_scans(record(tmp_path / "plain", Recording()), "/ouster/points", "/odom"))
    for scan, reference in zip(read_bag_scans(bag, "/ouster/points", "/odom"), plain, strict=True):
        offset = reference.pose[:3, :3] @ [1.0, 0.0, 2.0]
        np.testing.assert_allclose(scan.pose[:3, 3], reference.pose[:3, 3] + offset, atol=1e-9)
        np.testing.assert_allclose(scan.pose[:3, :3], reference.pose[:3, :3], atol=1e-12)


def test_a_cloud_already_in_the_odometry_frame_is_not_moved_again(tmp_path):
    bag = record(tmp_path / "world", Recording(cloud_frame="odom"))
    for scan in read_bag_scans(bag, "/ouster/points", "/odom"):
        np.testing.assert_array_equal(scan.pose, np.eye(4))


def test_foreign_topics_and_fields_are_refused_in_one_line(capsys, tmp_path, fake_encoder):
    bag = record(tmp_path / "drive", Recording(extra={"/imu": "sensor_msgs/msg/Imu"}))
    err = _one_error_line(*_map(capsys, bag, tmp_path / "a.npz", "--odom-topic", "/imu")[::2])
    assert "/imu" in err and "sensor_msgs/msg/Imu" in err and "nav_msgs/msg/Odometry" in err
    err = _one_error_line(*_map(capsys, bag, tmp_path / "b.npz", "--odom-topic", "/gps")[::2])
    assert "no topic '/gps'" in err and "/ouster/points" in err and "/odom" in err
    unlabelled = record(tmp_path / "unlabelled", Recording(fields=OUSTER_FIELDS[:4]))
    err = _one_error_line(*_map(capsys, unlabelled, tmp_path / "c.npz")[::2])
    assert "no field 'label'" in err and "intensity" in err and "--labels-field" in err
    flat = record(tmp_path / "flat", Recording(fields=(("x", 7), ("y", 7), ("label", 6))))
    with pytest.raises(FileFormatError, match=r"/ouster/points .*no field 'z'"):
        list(read_bag_scans(flat, "/ouster/points", "/odom"))
    with pytest.raises(InvalidInputError, match=str(flat)):
        list(read_bag_scans(flat, "/nothing", "/odom"))


def test_damaged_clouds_and_messages_are_refused_in_one_line(capsys, tmp_path, fake_encoder):
    narrow = record(tmp_path / "narrow", Recording(point_step=16))  # label at byte 16 of 16
    err = _one_error_line(*_map(capsys, narrow, tmp_path / "a.npz")[::2])
    assert "'label'" in err and "/ouster/points" in err and "16-byte point" in err
    bag = record(tmp_path / "drive", Recording())
    with sqlite3.connect(next(bag.glob("*.db3"))) as db:  # cut the last cloud short
        last = "(SELECT max(id) FROM messages)"
        db.execute(f"UPDATE messages SET data = substr(data, 1, 40) WHERE id = {last}")
    db.close()
    err = _one_error_line(*_map(capsys, bag, tmp_path / "b.npz")[::2])
    assert f"{bag}" in err and "a message on /ouster/points is damaged" in err
