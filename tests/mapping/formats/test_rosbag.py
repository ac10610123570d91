"""ROS bags: scans written and read back point for point, poses interpolated, bad bags refused."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.formats.rosbag import (
    BagScan,
    PoseTrack,
    fuse_bag,
    read_bag_scans,
    read_label_names,
)
from seminspect.mapping.formats.rosbag_writer import BagTopics, write_bag
from seminspect.mapping.formats.semantickitti import (
    label_table,
    read_calib,
    read_kitti_scan,
    read_poses,
    velodyne_poses,
)
from seminspect.mapping.ingest import integrate_labelled_scan
from seminspect.mapping.semantic_cloud import SemanticCloud

pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")

SEQ = "semantickitti/seq00_frames000-002"
NAMES = {0: "ground", 1: "car", 2: "tree"}


def _pose(yaw: float, xyz: tuple[float, float, float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("z", yaw).as_matrix()
    pose[:3, 3] = xyz
    return pose


def _synthetic_scans(count: int = 3) -> list[BagScan]:
    rng = np.random.default_rng(3)
    scans = []
    for k in range(count):
        points = rng.uniform(-20, 20, (500 + 10 * k, 3)).astype(np.float32).astype(np.float64)
        labels = rng.integers(0, 3, len(points))
        stamp = 1_700_000_000_000_000_000 + k * 100_000_000
        scans.append(BagScan(stamp, points, labels, _pose(0.3 * k, (2.0 * k, -k, 0.5))))
    return scans


def test_a_written_bag_reads_back_point_for_point(tmp_path) -> None:
    scans = _synthetic_scans()
    bag = write_bag(tmp_path / "scans", scans, NAMES)
    assert bag.is_dir() and not (tmp_path / ".scans.partial").exists()
    back = list(read_bag_scans(bag, "/points", "/odom", labels_field="label"))
    assert len(back) == len(scans)
    for wrote, read in zip(scans, back, strict=True):
        assert read.stamp_ns == wrote.stamp_ns
        np.testing.assert_array_equal(read.points, wrote.points)
        np.testing.assert_array_equal(read.labels, wrote.labels)
        np.testing.assert_allclose(read.pose, wrote.pose, atol=1e-12)
    assert read_label_names(bag) == NAMES
    assert next(read_bag_scans(bag, "/points", "/odom")).labels is None


def test_fusing_a_bag_equals_fusing_its_scans_directly(tmp_path, fake_encoder) -> None:
    scans = _synthetic_scans()
    bag = write_bag(tmp_path / "scans", scans, NAMES)
    seen: list[int] = []
    fused = fuse_bag(
        read_bag_scans(bag, "/points", "/odom", "label"), NAMES, fake_encoder, 0.15, seen.append
    )
    direct = SemanticCloud.empty(fake_encoder.dim, fake_encoder.name)
    for scan in scans:
        integrate_labelled_scan(
            direct, scan.points, scan.labels, scan.pose, names=NAMES, encoder=fake_encoder,
            radius=0.15,
        )  # fmt: skip
    assert seen == [1, 2, 3]
    np.testing.assert_allclose(fused.points, direct.points, atol=1e-9)
    np.testing.assert_allclose(fused.embeddings, direct.embeddings, atol=1e-6)


def test_poses_are_interpolated_between_odometry_messages() -> None:
    stamps = np.array([0, 1_000_000_000])
    positions = np.array([[0.0, 0.0, 0.0], [2.0, 4.0, 0.0]])
    quaternions = Rotation.from_euler("z", [[0.0], [np.pi / 2]]).as_quat()
    track = PoseTrack(stamps, positions, quaternions)
    middle = track.at(250_000_000)
    np.testing.assert_allclose(middle[:3, 3], [0.5, 1.0, 0.0])
    yaw = Rotation.from_matrix(middle[:3, :3]).as_euler("xyz")[2]
    assert yaw == pytest.approx(np.pi / 8)
    np.testing.assert_allclose(track.at(1_050_000_000)[:3, 3], [2.0, 4.0, 0.0])  # within the gap
    with pytest.raises(InvalidInputError, match="outside the odometry"):
        track.at(2_000_000_000)
    with pytest.raises(FileFormatError, match="NaN"):
        PoseTrack(stamps, positions * np.nan, quaternions)


def test_bad_topics_bags_and_outputs_are_refused(tmp_path) -> None:
    bag = write_bag(tmp_path / "scans", _synthetic_scans(1), NAMES, BagTopics(cloud="/velodyne"))
    with pytest.raises(InvalidInputError, match=r"no topic '/points' \(topics: .*/velodyne"):
        list(read_bag_scans(bag, "/points", "/odom"))
    with pytest.raises(InvalidInputError, match="is nav_msgs/msg/Odometry, not"):
        list(read_bag_scans(bag, "/odom", "/odom"))
    with pytest.raises(FileFormatError, match="no field 'intensity'"):
        list(read_bag_scans(bag, "/velodyne", "/odom", labels_field="intensity"))
    with pytest.raises(InvalidInputError, match="exists"):
        write_bag(bag, _synthetic_scans(1))
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"not a bag at all")
    with pytest.raises(FileFormatError, match="not a readable ROS bag"):
        list(read_bag_scans(junk, "/points", "/odom"))
    with pytest.raises(InvalidInputError, match="no such bag"):
        list(read_bag_scans(tmp_path / "missing", "/points", "/odom"))


def test_semantickitti_frames_survive_a_bag(tmp_path, shared_data) -> None:
    root = shared_data / SEQ
    poses = velodyne_poses(read_poses(root / "poses.txt"), read_calib(root / "calib.txt")["Tr"])
    times = np.loadtxt(root / "times.txt")
    frames = [
        read_kitti_scan(root / f"velodyne/{i:06d}.bin", root / f"labels/{i:06d}.label")
        for i in range(3)
    ]
    scans = [
        BagScan(round(times[i] * 1e9) + 1_000_000_000, f.points, f.semantic, poses[i])
        for i, f in enumerate(frames)
    ]
    bag = write_bag(tmp_path / "kitti", scans, label_table().names)
    back = list(read_bag_scans(bag, "/points", "/odom", labels_field="label"))
    assert [len(s.points) for s in back] == [len(f.points) for f in frames]
    for frame, pose, read in zip(frames, poses, back, strict=True):
        np.testing.assert_array_equal(read.points, frame.points)
        np.testing.assert_array_equal(read.labels, frame.semantic)
        # KITTI's text poses are orthonormal to ~1e-7; Odometry carries them as quaternions
        np.testing.assert_allclose(read.pose, pose, atol=1e-6)
    assert read_label_names(bag) == label_table().names
