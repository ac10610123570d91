import numpy as np
import pytest

from seminspect.core.errors import FileFormatError
from seminspect.mapping.formats.semantickitti import (
    fuse_kitti_scans,
    instance_boxes,
    label_table,
    read_calib,
    read_kitti_scan,
    read_poses,
    velodyne_poses,
)
from seminspect.perception.encoders import CaptionEncoder

SEQ = "semantickitti/seq00_frames000-002"


def test_label_table_is_the_published_one() -> None:
    table = label_table()
    assert table.names[10] == "car" and table.names[48] == "sidewalk"
    assert table.learning_map[252] == table.learning_map[10] == 1  # moving-car is a car
    assert table.thing_classes()[1] == "car"


def test_real_scan_and_labels(shared_data) -> None:
    root = shared_data / SEQ
    scan = read_kitti_scan(root / "velodyne/000000.bin", root / "labels/000000.label")
    assert scan.points.shape == (124_668, 3)
    names = label_table().names
    counts = {
        names[i]: int(n) for i, n in zip(*np.unique(scan.semantic, return_counts=True), strict=True)
    }
    assert counts["car"] == 4234 and counts["sidewalk"] == 26360 and counts["road"] == 34228
    boxes = instance_boxes(scan.points, scan.semantic, scan.instance, learning_class=1)
    assert len(boxes) > 5
    assert all(np.all(high - low < 8.0) for low, high in boxes)  # car-sized boxes


def test_three_posed_scans_average_across_views(shared_data, fake_encoder) -> None:
    root = shared_data / SEQ
    poses = velodyne_poses(read_poses(root / "poses.txt"), read_calib(root / "calib.txt")["Tr"])
    np.testing.assert_allclose(poses[0], np.eye(4), atol=1e-6)
    noisy = CaptionEncoder(fake_encoder.text, noise=1.0, seed=4)
    scans = [(root / f"velodyne/{i:06d}.bin", root / f"labels/{i:06d}.label") for i in range(3)]
    fused = fuse_kitti_scans(scans, poses, noisy, radius=0.15)
    cloud = fused.cloud
    assert cloud.counts.max() >= 3 and len(cloud) < fused.points.shape[0]
    # every point's embedding should approach its clean class caption as views accumulate
    clean = fake_encoder.encode_labels(["road"])[0]
    road = fused.cloud.similarity(clean[None, :])[:, 0]
    on_road = road > 0.3
    single = road[on_road & (cloud.counts == 1)].mean()
    several = road[on_road & (cloud.counts >= 3)].mean()
    assert several > single + 0.04


def test_malformed_kitti_files(tmp_path) -> None:
    scan = tmp_path / "000000.bin"
    scan.write_bytes(np.zeros(10, np.float32).tobytes())
    with pytest.raises(FileFormatError, match="16-byte"):
        read_kitti_scan(scan)
    scan.write_bytes(np.zeros((2, 4), np.float32).tobytes())
    labels = tmp_path / "000000.label"
    labels.write_bytes(np.zeros(3, np.uint32).tobytes())
    with pytest.raises(FileFormatError, match="expected 8"):
        read_kitti_scan(scan, labels)
    labels.write_bytes(np.array([10, 7777], np.uint32).tobytes())
    with pytest.raises(FileFormatError, match="label table"):
        read_kitti_scan(scan, labels)
    calib = tmp_path / "calib.txt"
    calib.write_text("P0: 1 2 3\n")
    with pytest.raises(FileFormatError, match="12 numbers"):
        read_calib(calib)
    poses = tmp_path / "poses.txt"
    poses.write_text("1 0 0 0 0 1 0 0 0 0 nan 0\n")
    with pytest.raises(FileFormatError, match="NaN"):
        read_poses(poses)
