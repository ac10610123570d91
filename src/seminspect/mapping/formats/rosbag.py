"""Reading ROS bags: labelled ``PointCloud2`` scans with ``Odometry``, through ``rosbags``
(:mod:`.rosbag_writer` writes them).

``rosbags`` is pure Python and reads ROS1 ``.bag`` files and ROS2 bag directories (sqlite3 or
mcap) without a ROS installation. What seminspect reads from a bag:

* a ``sensor_msgs/PointCloud2`` topic: ``x``, ``y``, ``z`` per point in the sensor frame and,
  optionally, an integer label field (SemanticKITTI's packing is understood: the semantic id is
  the lower 16 bits of a 32-bit label, the instance id the upper 16);
* a ``nav_msgs/Odometry`` topic: the sensor's pose in the map frame. Each cloud takes the pose
  interpolated at its header stamp (linear in position, slerp in rotation) between the two
  odometry messages around it; a cloud outside the odometry's time span by more than
  :data:`MAX_POSE_GAP_S` is refused, and so are two different poses at one stamp (a repeated
  message counts once). A cloud in the odometry's child frame takes its pose, one in the
  odometry's frame is in the map already, one in another frame needs a ``/tf_static`` chain
  from the child frame (``/tf`` is not read);
* optionally a ``std_msgs/String`` topic :data:`LABEL_NAMES_TOPIC` holding a JSON object of
  label id -> class name, which :func:`~seminspect.mapping.formats.rosbag_writer.write_bag`
  adds so the bag names its own labels; a bag without it is named by SemanticKITTI's label
  table, with a :class:`BagWarning`.

Fusing the scans into 001's metric-semantic cloud (Sec III-A.3) is
:func:`seminspect.mapping.ingest.integrate_labelled_scan`, one view per cloud.
"""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation, Slerp

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.mapping.formats.semantickitti import label_table
from seminspect.mapping.ingest import integrate_labelled_scan
from seminspect.mapping.semantic_cloud import SemanticCloud
from seminspect.perception.encoders import Encoder

#: A cloud may be this far outside the odometry's span and still take its end pose.
MAX_POSE_GAP_S = 0.1
LABEL_NAMES_TOPIC = "/seminspect/label_names"
CLOUD_TYPE = "sensor_msgs/msg/PointCloud2"
ODOMETRY_TYPE = "nav_msgs/msg/Odometry"
STRING_TYPE = "std_msgs/msg/String"
TF_STATIC_TOPIC = "/tf_static"
#: sensor_msgs/PointField datatypes as numpy types.
_FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
#: Odometry messages at one stamp whose poses differ less than this (m, rad) are one message.
_SAME_POSE = 1e-9


class BagWarning(UserWarning):
    """Something a bag lacks that reading works around (its label names, ...)."""


@dataclass(frozen=True)
class BagScan:
    """One cloud of a bag: its points in the sensor frame, labels, and the sensor's pose.

    Attributes:
        stamp_ns: header stamp in nanoseconds.
        points: ``(N, 3)`` float, sensor frame.
        labels: ``(N,)`` int semantic ids, or ``None`` when no label field was asked for.
        pose: ``(4, 4)`` float ``T_map_sensor``.
    """

    stamp_ns: int
    points: NDArray[np.float64]
    labels: NDArray[np.int64] | None
    pose: NDArray[np.float64]


def ros_typestore() -> Any:
    """The ROS2 Humble message definitions (rosbags' typestore); a clear error without rosbags."""
    try:
        from rosbags.typesys import Stores, get_typestore  # noqa: PLC0415 - optional dependency
    except ImportError:
        raise InvalidInputError(
            "ROS bags need the 'rosbags' package: pip install 'seminspect[ros]'"
        ) from None
    return get_typestore(Stores.ROS2_HUMBLE)


@contextmanager
def _opened(path: str | os.PathLike[str]) -> Iterator[Any]:
    """An open ``AnyReader`` over one ROS1 or ROS2 bag; unreadable bags are a FileFormatError."""
    typestore = ros_typestore()
    from rosbags.highlevel import AnyReader  # noqa: PLC0415 - optional dependency

    source = Path(path)
    _check_bag_path(source)
    try:
        reader = AnyReader([source], default_typestore=typestore)
        reader.open()
    except Exception as exc:  # rosbags raises its own error type per bag format
        raise FileFormatError(f"{source}: not a readable ROS bag ({exc})") from None
    try:
        yield reader
    except SeminspectError as exc:  # what went wrong inside names the bag it is in
        raise type(exc)(f"{source}: {exc}") from None
    finally:
        reader.close()


def _check_bag_path(source: Path) -> None:
    """Refuse a path that cannot be a bag, saying what is missing."""
    if not source.exists():
        raise InvalidInputError(f"{source}: no such bag")
    if not source.is_dir() or (source / "metadata.yaml").exists():
        return
    files = sorted(p.name for p in source.iterdir())
    storage = [name for name in files if name.endswith((".db3", ".mcap"))]
    hint = f"; give the storage file {storage[0]} itself" if len(storage) == 1 else ""
    raise FileFormatError(
        f"{source}: {'an empty directory' if not files else 'no metadata.yaml'}, not a ROS 2 "
        f"bag (its directory holds metadata.yaml beside .db3 or .mcap files){hint}"
    )


def _messages(reader, connections: list) -> Iterator[Any]:
    """The decoded messages of ``connections``; none for none (rosbags would read them all)."""
    for connection, _, raw in reader.messages(connections=connections) if connections else ():
        try:
            yield reader.deserialize(raw, connection.msgtype)
        except Exception as exc:  # rosbags raises its own error type per serialization
            raise FileFormatError(f"a message on {connection.topic} is damaged ({exc})") from None


def _stamp_ns(header) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def cloud_arrays(
    message, labels_field: str | None = None, topic: str = "the cloud topic"
) -> tuple[NDArray[np.float64], NDArray[np.int64] | None]:
    """Finite ``x y z`` points ``(N, 3)`` of a ``PointCloud2`` and its labels (lower 16 bits)."""
    fields = {f.name: f for f in message.fields}
    wanted = ["x", "y", "z", *([labels_field] if labels_field else [])]
    missing = [name for name in wanted if name not in fields]
    if missing:
        fix = "; name its label field with --labels-field" if missing[0] == labels_field else ""
        raise FileFormatError(
            f"the clouds on {topic} have no field {missing[0]!r} "
            f"(fields: {', '.join(fields) or 'none'}){fix}"
        )
    for name in wanted:
        size = np.dtype(_FIELD_TYPES.get(fields[name].datatype, "V0")).itemsize
        if not size or fields[name].count != 1 or fields[name].offset + size > message.point_step:
            raise FileFormatError(
                f"cloud field {name!r} on {topic} is not one number within its {message.point_step}"
                "-byte point"
            )
    order = ">" if message.is_bigendian else "<"
    dtype = np.dtype(
        {
            "names": wanted,
            "formats": [order + _FIELD_TYPES[fields[n].datatype] for n in wanted],
            "offsets": [fields[n].offset for n in wanted],
            "itemsize": message.point_step,
        }
    )
    count = message.width * message.height
    raw = np.asarray(message.data, dtype=np.uint8)
    if message.point_step <= 0 or raw.size < count * message.point_step:
        raise FileFormatError(f"a cloud holds {raw.size} bytes for {count} points")
    rows = np.frombuffer(raw[: count * message.point_step].tobytes(), dtype=dtype)
    points = np.column_stack([rows["x"], rows["y"], rows["z"]]).astype(np.float64)
    finite = np.all(np.isfinite(points), axis=1)
    labels = None
    if labels_field:
        labels = (rows[labels_field].astype(np.int64) & 0xFFFF)[finite]
    return points[finite], labels


def _frame(name: str) -> str:
    return name.lstrip("/")  # ROS 1 tf names may carry a leading slash


@dataclass(frozen=True)
class _Odometry:  # an odometry topic read: its poses of frame child in frame world
    track: PoseTrack
    world: str
    child: str


def _read_odometry(reader, topic: str) -> _Odometry:
    stamps, positions, rotations, frames = [], [], [], set()
    for message in _messages(reader, _topic_connections(reader, topic, ODOMETRY_TYPE)):
        pose = message.pose.pose
        stamps.append(_stamp_ns(message.header))
        positions.append([pose.position.x, pose.position.y, pose.position.z])
        q = pose.orientation
        rotations.append([q.x, q.y, q.z, q.w])
        frames.add((_frame(message.header.frame_id), _frame(message.child_frame_id)))
    if not stamps:
        raise FileFormatError(f"the odometry topic {topic} has no messages")
    if len(frames) > 1:
        raise FileFormatError(f"the odometry on {topic} mixes frames {sorted(frames)}")
    track = PoseTrack(np.asarray(stamps), np.asarray(positions), np.asarray(rotations), topic)
    return _Odometry(track, *frames.pop())


class PoseTrack:
    """Sensor poses interpolated over odometry stamps (in any order; repeats counted once)."""

    def __init__(
        self, stamps: NDArray, positions: NDArray, quaternions: NDArray, topic: str = "odometry"
    ):
        norms = np.linalg.norm(quaternions, axis=1)
        if not np.all(np.isfinite(positions)) or not np.all(norms > 0.5):
            raise FileFormatError(f"{topic} holds NaN poses or non-unit orientations")
        order = np.argsort(stamps, kind="stable")
        stamps, positions = np.asarray(stamps)[order], np.asarray(positions)[order]
        rotations = Rotation.from_quat(quaternions[order] / norms[order, None])
        keep = _new_stamps(stamps, positions, rotations, topic)
        self.stamps, self.positions, self.rotations = stamps[keep], positions[keep], rotations[keep]
        self.slerp = Slerp(self.stamps.astype(float), self.rotations) if keep.sum() > 1 else None

    def at(self, stamp_ns: int) -> NDArray[np.float64]:
        first, last = int(self.stamps[0]), int(self.stamps[-1])
        gap_s = max(first - stamp_ns, stamp_ns - last, 0) / 1e9
        if gap_s > MAX_POSE_GAP_S:
            raise InvalidInputError(
                f"a cloud at {stamp_ns / 1e9:.3f} s is {gap_s:.2f} s outside the odometry "
                f"({first / 1e9:.3f}-{last / 1e9:.3f} s)"
            )
        t = float(min(max(stamp_ns, first), last))
        transform = np.eye(4)
        transform[:3, 3] = [np.interp(t, self.stamps, self.positions[:, i]) for i in range(3)]
        rotation = self.slerp([t])[0] if self.slerp is not None else self.rotations[0]
        transform[:3, :3] = rotation.as_matrix()
        return transform


def _new_stamps(stamps: NDArray, positions: NDArray, rotations: Rotation, topic: str) -> NDArray:
    """Which messages to keep: a repeated stamp and pose (recorded twice) counts once."""
    repeat = np.diff(stamps) == 0
    moved = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    turned = (rotations[1:] * rotations[:-1].inv()).magnitude()
    clash = repeat & ((moved > _SAME_POSE) | (turned > _SAME_POSE))
    if clash.any():
        sec, nanosec = divmod(int(stamps[1:][clash][0]), 1_000_000_000)
        raise FileFormatError(
            f"{topic} has two different poses at stamp {sec}.{nanosec:09d} s; "
            "a cloud there has no one pose (re-record the odometry or drop one of them)"
        )
    return np.concatenate([[True], ~repeat])


def _topic_connections(reader, topic: str, msgtype: str) -> list:
    found = [c for c in reader.connections if c.topic == topic]
    if not found:
        topics = ", ".join(sorted({c.topic for c in reader.connections})) or "none"
        raise InvalidInputError(f"the bag has no topic {topic!r} (topics: {topics})")
    if any(c.msgtype != msgtype for c in found):
        raise InvalidInputError(f"topic {topic!r} is {found[0].msgtype}, not {msgtype}")
    return found


def read_bag_scans(
    path: str | os.PathLike[str],
    cloud_topic: str,
    odom_topic: str,
    labels_field: str | None = None,
) -> Iterator[BagScan]:
    """Every cloud of ``cloud_topic`` in bag order, posed from ``odom_topic`` (and /tf_static)."""
    with _opened(path) as reader:
        odometry = _read_odometry(reader, odom_topic)
        clouds = _topic_connections(reader, cloud_topic, CLOUD_TYPE)
        statics = _static_transforms(reader)  # before the clouds: one message stream at a time
        posers: dict[str, Callable[[int], NDArray[np.float64]]] = {}
        for message in _messages(reader, clouds):
            stamp = _stamp_ns(message.header)
            frame = _frame(message.header.frame_id)
            if frame not in posers:
                posers[frame] = _poser(odometry, statics, frame, (cloud_topic, odom_topic))
            points, labels = cloud_arrays(message, labels_field, cloud_topic)
            yield BagScan(stamp, points, labels, posers[frame](stamp))


def _poser(
    odometry: _Odometry, statics: Mapping, frame: str, topics: tuple[str, str]
) -> Callable[[int], NDArray[np.float64]]:
    """``stamp -> T_map_cloud`` for clouds in ``frame``."""
    if frame == odometry.child:
        return odometry.track.at
    if frame == odometry.world:  # already in the map: the odometry would move it twice
        return lambda _: np.eye(4)
    offset = _static_chain(statics, odometry.child, frame)
    if offset is None:
        raise InvalidInputError(
            f"the clouds on {topics[0]} are in frame {frame!r}, the odometry on {topics[1]} "
            f"poses {odometry.child!r} in {odometry.world!r}, and {TF_STATIC_TOPIC} links no "
            f"chain from {odometry.child!r} to {frame!r}: record {TF_STATIC_TOPIC}, or the "
            "clouds in the odometry's child frame"
        )
    return lambda stamp: odometry.track.at(stamp) @ offset


def _static_transforms(reader) -> dict[tuple[str, str], NDArray[np.float64]]:
    """``(parent, child) -> T_parent_child`` of every transform on :data:`TF_STATIC_TOPIC`."""
    found = [c for c in reader.connections if c.topic == TF_STATIC_TOPIC]
    edges = {}
    for message in _messages(reader, found):
        for item in message.transforms:
            t, q = item.transform.translation, item.transform.rotation
            transform = np.eye(4)
            transform[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
            transform[:3, 3] = [t.x, t.y, t.z]
            edges[(_frame(item.header.frame_id), _frame(item.child_frame_id))] = transform
    return edges


def _static_chain(
    edges: Mapping[tuple[str, str], NDArray[np.float64]], start: str, goal: str
) -> NDArray[np.float64] | None:
    """``T_start_goal`` along static transforms walked either way, or ``None``."""
    links: dict[str, list[tuple[str, NDArray]]] = {}
    for (parent, child), transform in edges.items():
        links.setdefault(parent, []).append((child, transform))
        links.setdefault(child, []).append((parent, np.linalg.inv(transform)))
    reached, queue = {start: np.eye(4)}, [start]
    while queue:
        frame = queue.pop(0)
        for neighbour, transform in links.get(frame, []):
            if neighbour not in reached:
                reached[neighbour] = reached[frame] @ transform
                queue.append(neighbour)
    return reached.get(goal)


def read_label_names(path: str | os.PathLike[str]) -> dict[int, str]:
    """The label names a bag carries on :data:`LABEL_NAMES_TOPIC`, else SemanticKITTI's.

    A bag without the topic (any bag seminspect did not write) gets SemanticKITTI's label table,
    with a :class:`BagWarning` saying so.
    """
    with _opened(path) as reader:
        found = [c for c in reader.connections if c.topic == LABEL_NAMES_TOPIC]
        for message in _messages(reader, found):
            text: str = getattr(message, "data", "")  # another type on the topic has none
            try:
                return {int(k): str(v) for k, v in json.loads(text).items()}
            except (TypeError, ValueError, AttributeError):
                raise FileFormatError(f"{LABEL_NAMES_TOPIC} is not a JSON object") from None
    warnings.warn(
        f"{path}: no {LABEL_NAMES_TOPIC} topic names the labels; using SemanticKITTI's label "
        "table (give --label-names to name them)",
        BagWarning,
        stacklevel=2,
    )
    return label_table().names


def fuse_bag(
    scans: Iterable[BagScan],
    names: Mapping[int, str],
    encoder: Encoder,
    radius: float,
    on_scan: Callable[[int], None] | None = None,
) -> SemanticCloud:
    """001's metric-semantic cloud (Sec III-A.3) from labelled bag scans, one view per cloud."""
    cloud = SemanticCloud.empty(encoder.dim, encoder.name)
    count = 0
    for scan in scans:
        if scan.labels is None:
            raise InvalidInputError("fusing a bag needs per-point labels (give --labels-field)")
        integrate_labelled_scan(
            cloud, scan.points, scan.labels, scan.pose, names=names, encoder=encoder, radius=radius
        )
        count += 1
        if on_scan:
            on_scan(count)
    if count == 0:
        raise InvalidInputError("the cloud topic has no messages")
    return cloud
