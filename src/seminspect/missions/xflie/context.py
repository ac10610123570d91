"""What every phase of an xFLIE mission shares: the robot, its map, the graph and the recorder."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from seminspect.core.params import InspectionParams
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie.config import ResolvedMissionConfig
from seminspect.missions.xflie.metrics import Timers
from seminspect.missions.xflie.navigation import Navigator
from seminspect.missions.xflie.recorder import MissionRecorder
from seminspect.perception.observation import Observation
from seminspect.platform.protocol import Platform
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Detection, Frame

#: Every DEPTH_STRIDE-th pixel (rows and columns) of a depth frame goes into the map.
DEPTH_STRIDE = 8


class MissionWatch(Protocol):
    """Something that looks at a mission while it runs (the live view). It only reads what it
    is shown, so a watched mission makes the same decisions as one nobody watches."""

    def frame(self, frame: Frame) -> None:
        """A camera frame, just put into the robot's map."""
        ...

    def detections(self, frame: Frame, detections: Sequence[Detection]) -> None:
        """What the mission kept of a frame's detections."""
        ...


@dataclass
class MissionContext:
    """The state the phases of one mission share.

    Attributes:
        min_height: object points below this height are bled pixels on the ground [m].
        unreachable: targets given up on (not reached, or too few views to inspect).
        frames_seen: camera frames taken so far (they number the saved images).
        on_step: called when a phase has made progress worth showing.
        watch: shown every frame and the detections kept of it (None: nobody watches).
    """

    config: ResolvedMissionConfig
    platform: Platform
    occupancy: VoxelMap
    graph: LayeredSemanticGraph
    navigator: Navigator
    recorder: MissionRecorder
    run: RunDirectory | None
    min_height: float
    unreachable: set[str] = field(default_factory=set)
    frames_seen: int = 0
    on_step: Callable[[], None] = lambda: None
    watch: MissionWatch | None = None

    @property
    def params(self) -> InspectionParams:
        return self.config.params

    @property
    def timers(self) -> Timers:
        return self.recorder.timers

    @property
    def time_left(self) -> float:
        return self.config.time_budget_s - self.platform.time

    def event(self, kind: str, **fields: object) -> None:
        self.recorder.event(kind, **fields)

    def capture(self, intensity: bool = False) -> Frame:
        """A camera frame, integrated into the robot's map; with its intensity image only when
        asked (an inspection view's pictures and features)."""
        with self.timers("sensing"):
            frame = self.platform.capture(intensity=intensity)
        self.integrate(frame)
        return frame

    def integrate(self, frame: Frame) -> None:
        """Put a frame's depth into the map."""
        with self.timers("sensing"):
            self.occupancy.integrate_frame(
                frame,
                stride=DEPTH_STRIDE,
                use_odometry=True,
                carving_spacing=self.config.map_carving_spacing,
            )
        self.frames_seen += 1
        if self.watch is not None:
            self.watch.frame(frame)

    def detect(self, frame: Frame, level: str, labels: Iterable[str]) -> list[Detection]:
        """Segmentations at or above the confidence threshold."""
        detections = self.platform.detect(frame, level, labels)
        kept = [d for d in detections if d.score >= self.config.min_score]
        if self.watch is not None:
            self.watch.detections(frame, kept)
        return kept

    def view_pose(self, image: str | None) -> Observation:
        """The robot's current pose as a view-pose observation (eq 9)."""
        return Observation.view_pose(
            self.platform.position,
            quat_from_yaw(self.platform.yaw),
            image=image,
            stamp=self.platform.time,
        )
