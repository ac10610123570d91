"""A mission seen while it runs: the state a live view draws, handed out at the view's pace.

:class:`LiveWatch` is the mission's :class:`~seminspect.missions.xflie.context.MissionWatch`. It
keeps the latest camera frame and the detections the mission kept of it, and whenever its
:class:`LiveFeed` is ready for more (a client is connected and the last state is old enough)
it hands the feed a :class:`LiveState`: the robot's pose and path, the frame and its detections,
the 3DLSG, the occupancy map, the phase and the next target with its eq (6) utility. It only
reads, so a watched mission decides exactly as an unwatched one; and it costs nothing while the
feed is not ready.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie.config import MissionConfig
from seminspect.missions.xflie.executive import XFlie
from seminspect.planning.utility import UtilityTerms
from seminspect.sensors import Detection, Frame
from seminspect.worlds import World


@dataclass(frozen=True)
class LiveState:
    """The mission as it stands, for one picture of the live view.

    The graph and the map are the mission's own, not copies: a feed reads them during
    :meth:`LiveFeed.publish` and keeps nothing of them after it returns.

    Attributes:
        sim_time, budget_s: simulated time so far and the mission's budget [s].
        phase: the executive's phase (``explore-360``, ``navigate``, ``inspect``, ...).
        trajectory: ``(n, 9)`` rows so far (time, true position, yaw, odometry position, yaw).
        frame: the latest camera frame (None before the first).
        detections: what the mission kept of that frame's detections.
        next_target: the last selection's target and its eq (6) terms (None: none chosen).
        detected, inspected: targets in the graph, and those of them inspected.
        ended: how the run ended (``completed``, ``interrupted``, ``failed``) in its last
            state; None while it runs.
    """

    sim_time: float
    budget_s: float
    phase: str
    trajectory: NDArray[np.float64]
    graph: LayeredSemanticGraph
    occupancy: VoxelMap
    frame: Frame | None
    detections: Sequence[Detection]
    next_target: UtilityTerms | None
    detected: int
    inspected: int
    ended: str | None = None


class LiveFeed(Protocol):
    """Where a watched mission's states go (the live view's server)."""

    def start(self, world: World) -> None:
        """The mission's world, before its first state."""
        ...

    def ready(self) -> bool:
        """Whether a new state is wanted now (cheap: asked at every frame)."""
        ...

    def publish(self, state: LiveState) -> None:
        """Take a state, reading the graph and the map before returning."""
        ...


def refuse_unwatchable(config: MissionConfig) -> None:
    """One clear error for a mission the live view cannot show (a team: it shows one robot)."""
    if config.robots:
        raise InvalidInputError("the live view shows one robot; a team cannot be watched yet")


class LiveWatch:
    """Shows a mission to a :class:`LiveFeed` (see the module docstring).

    A frame is published at the next frame, once the mission has had its detections: the view
    lags the mission by one frame and always shows a frame with its detections.
    """

    def __init__(self, feed: LiveFeed) -> None:
        self.feed = feed
        self._mission: XFlie | None = None
        self._frame: Frame | None = None
        self._detections: list[Detection] = []

    def attach(self, mission: XFlie, world: World) -> None:
        """Watch ``mission`` in ``world`` from its next frame on."""
        self.feed.start(world)
        self._mission = mission
        mission.ctx.watch = self

    def frame(self, frame: Frame) -> None:
        if self.feed.ready():
            self.publish()
        self._frame, self._detections = frame, []

    def detections(self, frame: Frame, detections: Sequence[Detection]) -> None:
        if frame is self._frame:
            self._detections.extend(detections)

    def publish(self, ended: str | None = None) -> None:
        """Hand the feed the mission's state now (nothing before :meth:`attach`)."""
        if self._mission is not None:
            self.feed.publish(self.state(ended))

    def state(self, ended: str | None = None) -> LiveState:
        """The attached mission's state, with the latest frame and its detections."""
        mission = self._mission
        if mission is None:
            raise RuntimeError("LiveWatch.state() before attach()")
        targets = mission.graph.targets()
        return LiveState(
            sim_time=mission.platform.time,
            budget_s=mission.config.time_budget_s,
            phase=mission.phase,
            trajectory=mission.platform.trajectory_rows(),
            graph=mission.graph,
            occupancy=mission.occupancy,
            frame=self._frame,
            detections=tuple(self._detections),
            next_target=mission.choice,
            detected=len(targets),
            inspected=sum(t.inspected for t in targets),
            ended=ended,
        )
