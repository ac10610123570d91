"""A run as one MCAP recording of standard ROS 2 messages, for Foxglove and the ROS 2 tools.

The recording is made after the mission from the run directory alone, as :mod:`.replay` makes
its bag: the world is regenerated from the run's seed and the LiDAR and the camera are cast
again from the robot's true poses along its trajectory. The mission and its other outputs are
therefore the same with or without a recording. Channels (docs/missions.md has the table):

* ``/tf`` (every trajectory row): ``map -> base_link``, the true pose, and
  ``map -> base_link_odom``, the pose the robot believed; ``/tf_static``: ``base_link ->
  camera`` (tilted down by the camera pitch) and ``camera -> camera_optical``;
* ``/odom``: the believed pose as ``nav_msgs/Odometry`` (child ``base_link``), so clouds read
  back with :func:`~seminspect.mapping.formats.rosbag.read_bag_scans` are placed as the robot
  placed them;
* ``/points``: the mission's LiDAR as labelled ``PointCloud2`` in ``base_link``, named on
  ``/seminspect/label_names``; ``/camera/image/compressed`` (JPEG of the grey image) and
  ``/camera/camera_info``: the mission's camera, ideal (no noise);
* ``/seminspect/lsg``: the final 3DLSG as it grew (:mod:`.lsg_markers`);
* ``/seminspect/events``: each line of ``events.jsonl`` as ``std_msgs/String`` JSON.

Log times are the simulated time (from 0 s); each stream is in time order, and they are merged.
A team's recording holds the robot of ``trajectory.csv`` (the explorer).
"""

from __future__ import annotations

import heapq
import json
import math
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from operator import itemgetter
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw, quat_from_yaw_pitch
from seminspect.graphs.lsg.io import load_graph
from seminspect.mapping.formats.rosbag import (
    CLOUD_TYPE,
    LABEL_NAMES_TOPIC,
    ODOMETRY_TYPE,
    STRING_TYPE,
)
from seminspect.mapping.formats.rosbag_writer import (
    TF_TYPE,
    cloud_message,
    header,
    label_names_message,
    odometry_message,
    open_bag,
    pose_message,
    string_message,
    transform_message,
)
from seminspect.missions.xflie.build import camera_pitch
from seminspect.missions.xflie.config import ResolvedMissionConfig, make_config, resolve
from seminspect.missions.xflie.layout import MCAP_FILE, load_run_world
from seminspect.missions.xflie.lsg_markers import MARKER_ARRAY_TYPE, marker_arrays, node_times
from seminspect.missions.xflie.replay import DEFAULT_SCAN_PERIOD_S, replay_scans, sampled_rows
from seminspect.runs.directory import load_events, read_run_config
from seminspect.runs.trajectory import load_trajectory
from seminspect.sensors import CameraModel, Lidar, render
from seminspect.worlds import World

IMAGE_TYPE = "sensor_msgs/msg/CompressedImage"
CAMERA_INFO_TYPE = "sensor_msgs/msg/CameraInfo"
#: A camera body frame (x forward, z up) to its optical frame (z forward, x right, y down).
_OPTICAL_QUAT = (-0.5, 0.5, -0.5, 0.5)
_JPEG = [cv2.IMWRITE_JPEG_QUALITY, 80]
#: One message: log time (ns), topic, type, message.
Stamped = tuple[int, str, str, Any]


@dataclass(frozen=True)
class RecordingRates:
    """Simulated seconds between the messages of the sampled channels (at least)."""

    scan_period_s: float = DEFAULT_SCAN_PERIOD_S
    image_period_s: float = 0.5
    graph_period_s: float = 1.0


@dataclass(frozen=True)
class _Run:
    """What a recording is made of: the run directory's files and its regenerated world."""

    config: ResolvedMissionConfig
    world: World
    trajectory: NDArray[np.float64]
    events: list[dict[str, Any]]
    root: Path

    @classmethod
    def read(cls, root: Path) -> _Run:
        trajectory = load_trajectory(root)
        if not len(trajectory):
            raise InvalidInputError(f"{root} has no trajectory to record")
        world = load_run_world(root)
        config = resolve(make_config(read_run_config(root)), world)
        events = sorted(load_events(root), key=itemgetter("t"))  # a team's robots interleave
        return cls(config, world, trajectory, events, root)


def record_run(
    run_dir: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    rates: RecordingRates = RecordingRates(),
    on_progress: Callable[[float, float], None] | None = None,
) -> Path:
    """Record a run directory as a new MCAP file ``out`` (default: ``<run>/run.mcap``).

    ``on_progress(simulated_s, end_s)`` follows the writing. The file appears only when it is
    complete; an existing ``out`` is refused.
    """
    run = _Run.read(Path(run_dir))
    target = Path(out) if out is not None else run.root / MCAP_FILE
    end_s = float(run.trajectory[-1, 0])
    with open_bag(target, storage="mcap") as bag:
        streams = _streams(bag.types, run, rates)
        for stamp_ns, topic, msgtype, message in heapq.merge(*streams, key=itemgetter(0)):
            bag.write(topic, msgtype, stamp_ns, message)
            if on_progress:
                on_progress(stamp_ns / 1e9, end_s)
    return target


def _streams(types: Mapping[str, Any], run: _Run, rates: RecordingRates) -> list[Iterator[Stamped]]:
    start_ns = _ns(run.trajectory[0, 0])
    pitch = math.radians(camera_pitch(run.config))
    return [
        iter([(start_ns, "/tf_static", TF_TYPE, _camera_mount(types, start_ns, pitch))]),
        iter([(start_ns, LABEL_NAMES_TOPIC, STRING_TYPE, _label_names(types, run.world))]),
        _poses(types, run.trajectory),
        _clouds(types, run, rates.scan_period_s),
        _images(types, run, pitch, rates.image_period_s),
        _graph(types, run, rates.graph_period_s),
        _events(types, run.events),
    ]


def _ns(seconds: float) -> int:
    return round(seconds * 1e9)  # as replay_scans stamps its scans


def _label_names(types: Mapping[str, Any], world: World) -> Any:
    return label_names_message(types, dict(enumerate(world.class_names)))


def _camera_mount(types: Mapping[str, Any], stamp_ns: int, pitch: float) -> Any:
    """The camera on the robot (at its origin, tilted) and the camera's optical frame."""
    mount = transform_message(
        types, stamp_ns, ("base_link", "camera"), (0, 0, 0), quat_from_yaw_pitch(0.0, pitch)
    )
    optical = transform_message(
        types, stamp_ns, ("camera", "camera_optical"), (0, 0, 0), _OPTICAL_QUAT
    )
    return types[TF_TYPE](transforms=[mount, optical])


def _poses(types: Mapping[str, Any], trajectory: NDArray[np.float64]) -> Iterator[Stamped]:
    """``/tf`` and ``/odom`` at every trajectory row."""
    for t, x, y, z, yaw, ox, oy, oz, oyaw in trajectory:
        stamp = _ns(t)
        true = transform_message(types, stamp, ("map", "base_link"), (x, y, z), quat_from_yaw(yaw))
        believed = ((ox, oy, oz), quat_from_yaw(oyaw))
        odom = transform_message(types, stamp, ("map", "base_link_odom"), *believed)
        yield stamp, "/tf", TF_TYPE, types[TF_TYPE](transforms=[true, odom])
        pose = pose_message(types, *believed)
        odometry = odometry_message(types, stamp, ("map", "base_link"), pose)
        yield stamp, "/odom", ODOMETRY_TYPE, odometry


def _clouds(types: Mapping[str, Any], run: _Run, period_s: float) -> Iterator[Stamped]:
    """The mission's LiDAR, cast again from the true poses, in ``base_link``."""
    lidar = Lidar(max_range=run.config.params.d_max)  # as the mission's platform has it
    for scan in replay_scans(run.world, run.trajectory, lidar, period_s):
        cloud = cloud_message(types, header(types, scan.stamp_ns, "base_link"), scan)
        yield scan.stamp_ns, "/points", CLOUD_TYPE, cloud


def _images(
    types: Mapping[str, Any], run: _Run, pitch: float, period_s: float
) -> Iterator[Stamped]:
    """The mission's camera rendered again from the true poses: JPEG and its calibration."""
    camera = CameraModel.from_params(run.config.params)
    for t, x, y, z, yaw, *_ in run.trajectory[sampled_rows(run.trajectory, period_s)]:
        frame = render(run.world, camera, (x, y, z), quat_from_yaw_pitch(yaw, pitch))
        encoded, jpeg = cv2.imencode(".jpg", frame.grey(), _JPEG)
        if not encoded:
            raise InvalidInputError(f"could not encode the camera image at {t:.1f} s")
        stamp = _ns(t)
        optical = header(types, stamp, "camera_optical")
        image = types[IMAGE_TYPE](header=optical, format="jpeg", data=jpeg.reshape(-1))
        yield stamp, "/camera/image/compressed", IMAGE_TYPE, image
        yield stamp, "/camera/camera_info", CAMERA_INFO_TYPE, _camera_info(types, optical, camera)


def _camera_info(types: Mapping[str, Any], optical: Any, camera: CameraModel) -> Any:
    """A pinhole without distortion: ``K``, and ``P = [K | 0]``."""
    k = camera.K
    return types[CAMERA_INFO_TYPE](
        header=optical, height=camera.height, width=camera.width, distortion_model="plumb_bob",
        d=np.zeros(5), k=k.reshape(-1), r=np.eye(3).reshape(-1),
        p=np.hstack([k, np.zeros((3, 1))]).reshape(-1), binning_x=0, binning_y=0,
        roi=types["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        ),
    )  # fmt: skip


def _graph(types: Mapping[str, Any], run: _Run, period_s: float) -> Iterator[Stamped]:
    graph = load_graph(run.root / "graph.json")
    times = node_times(graph, run.events, float(run.trajectory[-1, 0]))
    for stamp, markers in marker_arrays(types, graph, times, period_s):
        yield _ns(stamp), "/seminspect/lsg", MARKER_ARRAY_TYPE, markers


def _events(types: Mapping[str, Any], events: Sequence[Mapping[str, Any]]) -> Iterator[Stamped]:
    for event in events:
        message = string_message(types, json.dumps(event))
        yield _ns(event["t"]), "/seminspect/events", STRING_TYPE, message
