"""Writing ROS 2 bags through ``rosbags``: a bag that appears only when complete, the standard
messages seminspect writes, and :func:`write_bag`'s labelled scans.

:func:`open_bag` writes a ROS2 bag directory (sqlite3) or a single ``.mcap`` file (zstd chunks,
what Foxglove and ``ros2 bag`` open), ROS2 Humble message definitions either way. The bag is
written beside its name and renamed into place at the end, so a failure leaves no half bag.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.formats.rosbag import (
    CLOUD_TYPE,
    LABEL_NAMES_TOPIC,
    ODOMETRY_TYPE,
    STRING_TYPE,
    BagScan,
    ros_typestore,
)
from seminspect.mapping.semantic_cloud import as_transform

TF_TYPE = "tf2_msgs/msg/TFMessage"
_LABEL_FIELD_TYPE = 6  # uint32, as SemanticKITTI stores labels
Storage = Literal["sqlite3", "mcap"]


class BagWriter:
    """An open bag: messages go to a topic, whose connection is added with its first message."""

    def __init__(self, writer: Any, typestore: Any) -> None:
        self._writer = writer
        self._typestore = typestore
        self._connections: dict[str, Any] = {}
        #: The typestore's message classes by type name (``types["std_msgs/msg/String"]``).
        self.types: Mapping[str, Any] = typestore.types

    def write(self, topic: str, msgtype: str, stamp_ns: int, message: Any) -> None:
        """Serialise ``message`` (CDR) onto ``topic`` at log time ``stamp_ns``."""
        connection = self._connections.get(topic)
        if connection is None:
            connection = self._writer.add_connection(topic, msgtype, typestore=self._typestore)
            self._connections[topic] = connection
        self._writer.write(connection, stamp_ns, self._typestore.serialize_cdr(message, msgtype))


@contextmanager
def open_bag(path: str | os.PathLike[str], storage: Storage = "sqlite3") -> Iterator[BagWriter]:
    """A new bag at ``path``: a directory (sqlite3) or one ``.mcap`` file; an existing path is
    refused. Nothing is at ``path`` until the block ends without an error."""
    target = Path(path)
    if target.exists():
        raise InvalidInputError(f"{target} exists; choose a new bag name")
    typestore = ros_typestore()
    from rosbags.rosbag2 import (  # noqa: PLC0415 - optional dependency
        CompressionFormat,
        CompressionMode,
        StoragePlugin,
        Writer,
    )

    # a name a run directory knows for a leftover of its file (runs.directory.RunLayout)
    partial = target.with_name(f".{target.name}.bag.partial")
    _remove(partial)
    mcap = storage == "mcap"
    writer = Writer(
        partial, version=9, storage_plugin=StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3
    )
    if mcap:  # zstd chunks: LiDAR clouds shrink to about 40 %
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    try:
        with writer:
            yield BagWriter(writer, typestore)
        # an MCAP bag directory holds the file and a metadata.yaml that only repeats it
        (partial / f"{partial.name}.mcap" if mcap else partial).rename(target)
    finally:
        _remove(partial)


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


# --- messages ------------------------------------------------------------------------------------


def header(types: Mapping[str, Any], stamp_ns: int, frame: str) -> Any:
    """``std_msgs/Header`` at ``stamp_ns`` in ``frame``."""
    stamp = types["builtin_interfaces/msg/Time"](
        sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000
    )
    return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def string_message(types: Mapping[str, Any], text: str) -> Any:
    return types[STRING_TYPE](text)


def vector_message(types: Mapping[str, Any], name: str, values: ArrayLike) -> Any:
    """A ``geometry_msgs`` vector type (``Point``, ``Vector3``, ``Quaternion``) of ``values``."""
    return types[f"geometry_msgs/msg/{name}"](*np.asarray(values, dtype=float).tolist())


def pose_message(types: Mapping[str, Any], position: ArrayLike, quaternion: ArrayLike) -> Any:
    """``geometry_msgs/Pose`` from a position and an ``x y z w`` quaternion."""
    return types["geometry_msgs/msg/Pose"](
        position=vector_message(types, "Point", position),
        orientation=vector_message(types, "Quaternion", quaternion),
    )


def transform_message(
    types: Mapping[str, Any],
    stamp_ns: int,
    frames: tuple[str, str],
    position: ArrayLike,
    quaternion: ArrayLike,
) -> Any:
    """``geometry_msgs/TransformStamped``: ``frames[1]`` posed in ``frames[0]``."""
    transform = types["geometry_msgs/msg/Transform"](
        translation=vector_message(types, "Vector3", position),
        rotation=vector_message(types, "Quaternion", quaternion),
    )
    return types["geometry_msgs/msg/TransformStamped"](
        header=header(types, stamp_ns, frames[0]), child_frame_id=frames[1], transform=transform
    )


def odometry_message(
    types: Mapping[str, Any], stamp_ns: int, frames: tuple[str, str], pose: Any
) -> Any:
    """``nav_msgs/Odometry``: the ``geometry_msgs/Pose`` of ``frames[1]`` in ``frames[0]``, at
    rest, without covariances."""
    covariance = np.zeros(36)
    twist = types["geometry_msgs/msg/Twist"](
        linear=vector_message(types, "Vector3", (0.0, 0.0, 0.0)),
        angular=vector_message(types, "Vector3", (0.0, 0.0, 0.0)),
    )
    return types[ODOMETRY_TYPE](
        header=header(types, stamp_ns, frames[0]),
        child_frame_id=frames[1],
        pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=covariance),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=covariance),
    )


def cloud_message(types: Mapping[str, Any], cloud_header: Any, scan: BagScan) -> Any:
    """``sensor_msgs/PointCloud2`` of ``x y z`` float32 and ``label`` uint32 (0 without labels)."""
    field = types["sensor_msgs/msg/PointField"]
    rows = np.zeros(
        len(scan.points), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("label", "<u4")]
    )
    for axis, name in enumerate("xyz"):
        rows[name] = scan.points[:, axis]
    if scan.labels is not None:
        rows["label"] = scan.labels
    fields = [field(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate("xyz")]
    fields.append(field(name="label", offset=12, datatype=_LABEL_FIELD_TYPE, count=1))
    return types[CLOUD_TYPE](
        header=cloud_header, height=1, width=len(rows), fields=fields, is_bigendian=False,
        point_step=16, row_step=16 * len(rows), data=rows.view(np.uint8).reshape(-1),
        is_dense=True,
    )  # fmt: skip


def label_names_message(types: Mapping[str, Any], label_names: Mapping[int, str]) -> Any:
    """The :data:`~seminspect.mapping.formats.rosbag.LABEL_NAMES_TOPIC` message: id -> name."""
    return string_message(types, json.dumps({str(k): v for k, v in sorted(label_names.items())}))


# --- labelled scans ------------------------------------------------------------------------------


@dataclass(frozen=True)
class BagTopics:
    """Topic and frame names of a bag :func:`write_bag` makes."""

    cloud: str = "/points"
    odometry: str = "/odom"
    map_frame: str = "map"
    sensor_frame: str = "lidar"


def write_bag(
    path: str | os.PathLike[str],
    scans: Iterable[BagScan],
    label_names: Mapping[int, str] | None = None,
    topics: BagTopics = BagTopics(),
) -> Path:
    """Write scans as ``PointCloud2`` (x, y, z float32, label uint32) plus ``Odometry``.

    The bag is a ROS2 bag directory (sqlite3, ROS2 Humble message definitions); ROS1 bags are
    read, not written. It appears only when complete: written beside, then renamed into place.
    """
    with open_bag(path) as bag:
        pending_names = label_names  # written once, with the first scan
        for scan in scans:
            if pending_names is not None:
                message = label_names_message(bag.types, pending_names)
                bag.write(LABEL_NAMES_TOPIC, STRING_TYPE, scan.stamp_ns, message)
                pending_names = None
            _write_scan(bag, scan, topics)
    return Path(path)


def _write_scan(bag: BagWriter, scan: BagScan, topics: BagTopics) -> None:
    """One scan: its sensor pose as ``Odometry``, then its cloud, both at the scan's stamp."""
    types, stamp = bag.types, scan.stamp_ns
    pose = as_transform(scan.pose, "scan pose")
    geometry = pose_message(types, pose[:3, 3], Rotation.from_matrix(pose[:3, :3]).as_quat())
    odometry = odometry_message(types, stamp, (topics.map_frame, topics.sensor_frame), geometry)
    bag.write(topics.odometry, ODOMETRY_TYPE, stamp, odometry)
    cloud = cloud_message(types, header(types, stamp, topics.sensor_frame), scan)
    bag.write(topics.cloud, CLOUD_TYPE, stamp, cloud)
