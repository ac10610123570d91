"""Phase 1 of 001 in the simulator: drive a world's path and fuse LiDAR scans with camera segments.

001 Sec III-A builds its task-agnostic metric-semantic map from time-synchronised, calibrated
camera images and LiDAR scans (Sec IV: an OAK-D LR camera and a 128-beam Ouster OS1). Here a
ground robot drives ``World.metadata["drive_path"]`` and, every ``spacing`` metres, takes a scan
and a frame at the same instant:

1. the frame's labels stand in for 001's segmentation (YOLO terrain classes, FastSAM masks): one
   segment per object and one per ground class (sidewalk, grass, asphalt, ...);
2. the encoder embeds every segment once per frame, one view (Sec III-A.2); the caption encoder
   embeds the segment's class with fresh noise per view;
3. the scan, in the LiDAR's frame, is projected into the segmentation with the rig's calibration
   and fused into the cloud (Sec III-A.3, :func:`~seminspect.mapping.semantic_cloud.fuse_scan`).
   The camera's depth image hides points the camera cannot see: edges seen differently by the
   two offset sensors (the bleeding of 001 Sec IV-B) and, with the tight default tolerance
   (0.1 m + 1 %), ground far away, where one pixel at a grazing angle spans metres of ground
   (``d^2 * pixel angle / height``: 1.8 m at 26 m) and would smear labels across terrain borders.

Poses are the true ones: 001 takes them from LIO-SAM, whose drift is out of scope here.
:func:`evaluate_on_world` scores a phase-2 graph of such a cloud against the world's truth.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
import shapely
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field
from scipy import ndimage
from shapely.geometry import Polygon

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.validation import build
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.terrain.evaluate import (
    ObjectQuality,
    PlaceQuality,
    TerrainQuality,
    match_boxes,
    match_class,
    predicted_boxes,
    score_places,
)
from seminspect.graphs.terrain.prompting import TaskPoints
from seminspect.graphs.terrain.scene_graph import TerrainBuild
from seminspect.mapping.semantic_cloud import (
    CameraSegmentation,
    SemanticCloud,
    fuse_scan,
    transform_points,
)
from seminspect.perception.encoders import Encoder, Segment, TextEncoder
from seminspect.robot import Robot
from seminspect.sensors import CameraModel, Frame, Lidar, render
from seminspect.worlds import World, generate_world
from seminspect.worlds.outdoor import drive_path, terrain_patches
from seminspect.worlds.shapes import pose_matrix

#: ``T_body_optical``: the optical frame of OpenCV (x right, y down, z forward), which
#: ``CameraSegmentation`` expects, in the camera's body frame (x forward, y left, z up).
BODY_FROM_OPTICAL = np.array(
    [[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


@dataclass(frozen=True)
class SensorRig:
    """The robot's camera and LiDAR, after the sensors of 001 Sec IV.

    Attributes:
        camera: 640 x 400 pixels with the OAK-D LR's 80 deg horizontal field of view; depth and
            segments out to 40 m.
        lidar: 128 beams over the OS1-128's 45 deg vertical field (-22.5..+22.5 deg), 1024
            columns, 100 m.
        camera_height: camera above the ground (metres).
        lidar_offset: LiDAR position in the body frame relative to the camera (metres); the
            offset makes the two sensors see past object edges differently, as on a real robot.
    """

    camera: CameraModel = field(default_factory=lambda: CameraModel(640, 400, 80.0, 40.0))
    lidar: Lidar = field(
        default_factory=lambda: Lidar(128, -22.5, 22.5, 360.0 / 1024, max_range=100.0)
    )
    camera_height: float = 0.8
    lidar_offset: tuple[float, float, float] = (-0.1, 0.0, 0.25)


class MappingParams(BaseModel):
    """How phase 1 samples the drive and fuses the scans."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    spacing: float = Field(1.0, gt=0, le=50, description="metres driven between frames")
    radius: float = Field(0.15, gt=0, le=5, description="scan-to-map association radius")
    depth_tolerance: float = Field(
        0.1, ge=0, description="a scan point is seen by the camera within this depth (metres)"
    )
    depth_tolerance_per_m: float = Field(
        0.01, ge=0, description="plus this much per metre of depth"
    )


def make_mapping_params(values: dict[str, Any]) -> MappingParams:
    """Validate raw values, with one readable error line."""
    return build(MappingParams, values, "mapping parameter")


@dataclass
class MappingRun:
    """The cloud of one drive and what it took.

    Attributes:
        cloud: the metric-semantic cloud; its ``source`` names the world, scenario and seed.
        frames: scan + frame pairs fused.
        distance: metres driven.
        fused: scan points that took an embedding (associated plus added).
        seconds: time spent in ``sensors`` (ray casting), ``segments`` (segmentation and
            embedding), ``fusion`` and ``total``.
    """

    cloud: SemanticCloud
    frames: int
    distance: float
    fused: int
    seconds: dict[str, float]


def drive_samples(
    waypoints: NDArray[np.float64], spacing: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Points at most ``spacing`` apart along the polyline, and the heading of each one's leg.

    The first point is the first waypoint, facing along the first leg; every waypoint is a
    sample, so the robot turns at the corners.
    """
    points = [waypoints[0]]
    yaws: list[float] = []
    for start, end in itertools.pairwise(waypoints):
        leg = end - start
        length = float(np.hypot(*leg))
        if length == 0.0:
            continue
        yaw = math.atan2(leg[1], leg[0])
        if not yaws:
            yaws.append(yaw)  # the start faces along the first leg
        steps = math.ceil(length / spacing - 1e-9)
        points.extend(start + leg * (k / steps) for k in range(1, steps + 1))
        yaws.extend([yaw] * steps)
    if len(points) < 2:
        raise PlanningError("the drive path has no length")
    return np.asarray(points), np.asarray(yaws)


def frame_segments(frame: Frame, world: World) -> tuple[NDArray[np.int64], list[Segment]]:
    """Segment ids per pixel and the segments: one per object, one per ground class.

    Pixels that see nothing or an unlabelled (``background``) face belong to no segment (-1).
    A segment carries its class as label and its bounding-box crop of the grey image as RGB,
    for encoders that embed pixels.
    """
    classes = len(world.class_names)
    key = np.where(
        frame.instance > 0, frame.instance.astype(np.int64) + classes, frame.class_id
    ).astype(np.int64)
    valid = np.isfinite(frame.depth) & (key > 0)
    keys, first, inverse = np.unique(key[valid], return_index=True, return_inverse=True)
    ids = np.full(frame.shape, -1, dtype=np.int64)
    ids[valid] = inverse
    segment_class = frame.class_id[valid][first]
    rgb = np.repeat(frame.grey()[..., None], 3, axis=2)
    boxes = ndimage.find_objects(ids + 1, max_label=len(keys))
    segments = [
        Segment(label=world.class_names[int(c)], image=rgb[box])
        for c, box in zip(segment_class, boxes, strict=True)
    ]
    return ids, segments


def rig_poses(
    rig: SensorRig, camera_position: NDArray[np.float64], yaw: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``T_world_lidar`` (body axes) and ``T_world_camera`` (optical axes) for a robot pose."""
    body = pose_matrix(camera_position, yaw)
    return body @ pose_matrix(rig.lidar_offset), body @ BODY_FROM_OPTICAL


def _world_source(world: World, params: MappingParams, frames: int) -> dict[str, Any]:
    source: dict[str, Any] = {"frames": frames, **params.model_dump()}
    if "generator" in world.metadata:  # a built-in world: it can be regenerated to score against
        source["world"] = {
            "name": world.metadata["generator"],
            "scenario": world.metadata.get("scenario"),
            "seed": world.seed,
            "options": world.metadata.get("options", {}),
        }
    return source


def source_world(cloud: SemanticCloud) -> World | None:
    """The built-in world a cloud was mapped in, regenerated from its source record, if any."""
    spec = cloud.source.get("world")
    if spec is None:
        return None
    try:
        return generate_world(
            spec["name"], spec["scenario"], int(spec["seed"]), **dict(spec["options"])
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"the cloud's source record names no usable world ({exc})"
        ) from None


def map_world(
    world: World,
    encoder: Encoder,
    *,
    params: MappingParams | None = None,
    rig: SensorRig | None = None,
    on_frame: Callable[[int, int], None] | None = None,
) -> MappingRun:
    """Drive the world's path and build its metric-semantic cloud (001 Sec III-A).

    Args:
        world: a world with a ``drive_path`` (the ``outdoor`` world has one).
        encoder: embeds the segments; a caption encoder with noise gives each view its own.
        params: frame spacing and association radius.
        rig: the sensors and their mounting.
        on_frame: called with ``(frames done, frames in total)`` after each frame.
    """
    params = params or MappingParams()
    rig = rig or SensorRig()
    points, yaws = drive_samples(drive_path(world), params.spacing)
    height = world.ground_z + rig.camera_height
    robot = Robot(
        world, body_height=rig.camera_height, position=(*points[0], height), yaw=float(yaws[0])
    )
    fusion = _Fusion(world, rig, encoder, SemanticCloud.empty(encoder.dim, encoder.name))
    start = time.perf_counter()
    for index, (point, yaw) in enumerate(zip(points, yaws, strict=True)):
        if index:
            move = robot.move_to(point, float(yaw))
            if not move.reached:
                raise PlanningError(f"the drive path is blocked near {np.round(point, 2).tolist()}")
        fusion.fuse(robot.position, robot.yaw, params)
        if on_frame:
            on_frame(index + 1, len(points))
    seconds = {**fusion.seconds, "total": time.perf_counter() - start}
    fusion.cloud.source = _world_source(world, params, len(points))
    return MappingRun(fusion.cloud, len(points), robot.distance_travelled, fusion.fused, seconds)


@dataclass
class _Fusion:
    """One drive's cloud, with the points fused and the time spent per step so far."""

    world: World
    rig: SensorRig
    encoder: Encoder
    cloud: SemanticCloud
    fused: int = 0
    seconds: dict[str, float] = field(
        default_factory=lambda: dict.fromkeys(("sensors", "segments", "fusion"), 0.0)
    )

    def fuse(self, camera_position: NDArray[np.float64], yaw: float, params: MappingParams) -> None:
        """Scan, render, segment, embed and fuse at one robot pose."""
        t0 = time.perf_counter()
        T_world_lidar, T_world_camera = rig_poses(self.rig, camera_position, yaw)
        orientation = quat_from_yaw(yaw)
        scan = self.rig.lidar.scan(self.world, T_world_lidar[:3, 3], orientation)
        frame = render(self.world, self.rig.camera, camera_position, orientation)
        t1 = time.perf_counter()
        ids, segments = frame_segments(frame, self.world)
        dim = self.encoder.dim
        embeddings = (
            self.encoder.encode_segments(segments) if segments else np.zeros((0, dim), np.float32)
        )
        segmentation = CameraSegmentation(
            ids,
            embeddings,
            self.rig.camera.K,
            np.linalg.inv(T_world_camera) @ T_world_lidar,
            depth=frame.depth,
            depth_tolerance=params.depth_tolerance,
            depth_tolerance_per_m=params.depth_tolerance_per_m,
        )
        t2 = time.perf_counter()
        lidar_from_world = cast("NDArray[np.float64]", np.linalg.inv(T_world_lidar))
        in_lidar = transform_points(lidar_from_world, scan.points)
        stats = fuse_scan(self.cloud, in_lidar, T_world_lidar, segmentation, radius=params.radius)
        self.fused += stats.associated + stats.added
        self.seconds["sensors"] += t1 - t0
        self.seconds["segments"] += t2 - t1
        self.seconds["fusion"] += time.perf_counter() - t2


def truth_boxes(world: World, class_name: str) -> list[tuple[NDArray, NDArray]]:
    """Axis-aligned boxes of the world's objects of one class."""
    return [(info.bbox_min, info.bbox_max) for info in world.instances_of(class_name)]


def evaluate_on_world(
    build: TerrainBuild,
    world: World,
    encoder: TextEncoder,
    *,
    iou: float = 0.3,
    min_patch_area: float = 10.0,
) -> TerrainQuality:
    """Score a phase-2 graph against the world it was mapped in (001 Sec IV, with ground truth).

    Objects: the nodes of each object prompt against the world's objects of the class the
    prompt names (precision and recall at ``iou``). Places: for each terrain prompt, the true
    patches of its class (:func:`~seminspect.graphs.terrain.evaluate.score_places`, tolerance
    one grid cell, since places sit at cell centres and closing grows a grid by up to a cell),
    and the share of the prompt's layer-1 points that lie on those patches.
    """
    scene = build.scene
    objects: dict[str, ObjectQuality] = {}
    object_classes = sorted({info.class_name for info in world.instances.values()})
    for prompt in scene.prompts.objects:
        match = match_class(encoder, prompt, object_classes, scene.calibration.objects)
        boxes = truth_boxes(world, match.truth) if match.truth else []
        scores = match_boxes(predicted_boxes(scene, prompt), boxes, iou)
        objects[prompt] = ObjectQuality(match, scores)
    patches = terrain_patches(world)
    terrain_classes = sorted({cls for cls, _ in patches})
    places: dict[str, PlaceQuality] = {}
    for prompt in scene.prompts.terrain:
        match = match_class(encoder, prompt, terrain_classes, scene.calibration.terrain)
        mine = [polygon for cls, polygon in patches if cls == match.truth]
        place_scores = score_places(
            scene, prompt, mine, min_area=min_patch_area, tolerance=scene.params.cell_size
        )
        places[prompt] = PlaceQuality(match, _points_on(scene.layer1, prompt, mine), place_scores)
    return TerrainQuality(objects, places)


def _points_on(layer: TaskPoints | None, prompt: str, patches: list[Polygon]) -> float | None:
    """Share of a terrain prompt's layer-1 points that lie on a true patch of its class."""
    if layer is None:
        return None
    rows = layer.of(prompt)
    if rows.size == 0:
        return None
    if not patches:
        return 0.0
    xy = layer.points[rows, :2]
    return float(shapely.intersects_xy(shapely.union_all(patches), xy[:, 0], xy[:, 1]).mean())
