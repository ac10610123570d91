"""When a level is done: back near its start, the view matches its first images (000 eq 8).

The level's first ``N`` images (``horizon_N``) are the candidates. Once the robot has left
``d_thresh^I`` of the level's start, every new view is compared with them; a scene similarity
``Γ >= Γ_thresh`` ends the level. A sweep of more than a full turn around the target, or the
configured number of poses, ends it too, as a safety cap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from seminspect.missions.xflie.context import MissionContext
from seminspect.perception.similarity import (
    ORB_GAMMA_THRESHOLD,
    ImageFeatures,
    SceneMatcher,
    scene_similarity,
)
from seminspect.platform.protocol import heading_to
from seminspect.sensors import Frame

#: A level also ends (as a safety cap) once the robot has circled the target this far [rad].
LEVEL_SWEEP_CAP = 2.0 * math.pi + math.radians(40)


@dataclass
class LevelState:
    """Bookkeeping for the level being inspected."""

    start: NDArray[np.float64]
    candidates: list[ImageFeatures] = field(default_factory=list)
    left_start: bool = False
    poses: int = 0
    sweep: float = 0.0
    last_bearing: float | None = None


class LevelCompletion:
    """Eq (8) scene similarity, with a sweep and pose cap as a safety net."""

    def __init__(self, ctx: MissionContext) -> None:
        self.ctx = ctx
        self.matcher = SceneMatcher()
        gamma = ctx.config.gamma_thresh
        #: ``Γ_thresh`` of eq (8): the configured one, or the ORB matcher's calibration.
        self.gamma_thresh = ORB_GAMMA_THRESHOLD if gamma is None else gamma

    def is_complete(
        self, state: LevelState, frame: Frame, target_id: str, centre: NDArray[np.float64]
    ) -> bool:
        """Whether the view in ``frame`` ends the level (``centre``: the target seen so far)."""
        ctx = self.ctx
        params = ctx.params
        with ctx.timers("perception"):
            features = self.matcher.features(frame.grey())
        distance = float(np.linalg.norm(ctx.platform.position - state.start))
        state.left_start |= distance > params.d_thresh_I
        self._track_sweep(state, centre)
        if len(state.candidates) < params.horizon_N:
            state.candidates.append(features)
            return False
        if state.left_start:
            with ctx.timers("perception"):
                gamma = scene_similarity(
                    self.matcher, features, state.candidates, distance, params.d_thresh_I
                )
            if gamma >= self.gamma_thresh:
                ctx.recorder.level_ended("similarity")
                ctx.event(
                    "level-complete",
                    target=target_id,
                    gamma=round(gamma, 3),
                    poses=state.poses,
                    reason="similarity",
                )
                return True
        if (
            state.sweep >= LEVEL_SWEEP_CAP
            or state.poses >= ctx.config.inspection.max_poses_per_level
        ):
            ctx.recorder.level_ended("cap")
            ctx.event("level-complete", target=target_id, poses=state.poses, reason="cap")
            return True
        return False

    def _track_sweep(self, state: LevelState, centre: NDArray[np.float64]) -> None:
        """Add the angle the robot turned around ``centre`` since the last view."""
        bearing = heading_to(centre, self.ctx.platform.position)
        if state.last_bearing is not None:
            state.sweep += abs(math.remainder(bearing - state.last_bearing, math.tau))
        state.last_bearing = bearing
