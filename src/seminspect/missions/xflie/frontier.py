"""Pure frontier exploration: the exploration baseline of 000 Table 6 (GBPlanner2.0's role).

The robot, its sensors, its map, its perception and its navigator are those of an xFLIE
mission (:class:`~seminspect.missions.xflie.XFlie`, which this class extends), and every frame
still registers its target detections in the Target layer (eqs 3-5). What differs is the
decision: the robot never goes to a target and never inspects one. It surveys where it stands,
then drives to the frontier of best ``gain * exp(-lambda * distance)``
(:class:`~seminspect.planning.frontier.FrontierPlanner`) and surveys there, until no frontier
is left or the budget is spent.

Table 6 scores an explorer on what it observed (000 Sec VII-D): each target's coverage is the
box around the points of every mask that was registered to it, from any range up to ``d_max``,
and its position is the Target node's (the merged observations of eqs 3-5, without the
containment-polygon refinement that an inspection brings).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie import MissionProgress, XFlie
from seminspect.missions.xflie.config import ResolvedMissionConfig
from seminspect.missions.xflie.exploration import (
    FRONTIER_MIN_DISTANCE,
    FRONTIER_RADIUS,
    FRONTIER_TRIES,
    Exploration,
)
from seminspect.missions.xflie.sightings import register_targets
from seminspect.perception.detections import detection_points
from seminspect.planning.frontier import FrontierPlanner, ScoredFrontier
from seminspect.platform.protocol import Platform
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Frame


class FrontierMission(XFlie):
    """A mission that only explores (see the module docstring); same arguments as
    :class:`~seminspect.missions.xflie.XFlie`."""

    def __init__(
        self,
        config: ResolvedMissionConfig,
        platform: Platform,
        occupancy: VoxelMap,
        *,
        ground_z: float,
        run: RunDirectory | None = None,
        progress: Callable[[MissionProgress], None] | None = None,
    ) -> None:
        super().__init__(config, platform, occupancy, ground_z=ground_z, run=run, progress=progress)
        self.frontiers = FrontierPlanner(min_distance=FRONTIER_MIN_DISTANCE)
        self.exploration = Exploration(self.ctx, on_frame=self._observe)
        #: Whether frontiers are left that the time left cannot reach.
        self.budget_bound = False

    def _build_target_phases(self) -> None:
        """None: targets are registered as they are seen, never approached or inspected."""

    def execute(self) -> str:
        """Survey, then hop from frontier to frontier; returns why it stopped."""
        self._phase("explore-360")
        self.navigator.sense_lidar()
        self.exploration.survey()
        while self.time_left > 0 and self.explore():
            pass
        out_of_time = self.time_left <= 0 or self.budget_bound
        self.stop_reason = "time budget spent" if out_of_time else "no frontier left"
        return self.stop_reason

    def explore(self, keep: Callable[[NDArray[np.float64]], bool] | None = None) -> bool:
        """Drive to the best reachable frontier and survey there; False if none is left
        (among those whose goal ``keep`` accepts, when given)."""
        self._phase("explore-frontier")
        candidates = [c for c in self._candidates() if keep is None or keep(c.frontier.goal)]
        for choice in candidates[:FRONTIER_TRIES]:
            goal = choice.frontier.goal
            self.frontiers.mark_spent(goal)
            if self.navigator.go_to(goal, radius=FRONTIER_RADIUS):
                self.ctx.event(
                    "frontier",
                    goal=goal.round(2).tolist(),
                    cells=choice.frontier.cells,
                    gain_m2=round(choice.gain_m2, 1),
                    utility=round(choice.utility, 3),
                )
                self.exploration.survey()
                return True
        return False

    def _candidates(self) -> list[ScoredFrontier]:
        """Frontiers ranked by utility, less those the robot could not reach within the time
        left even in a straight line (a hop is not started that the budget cannot pay for)."""
        here = self.platform.position
        band = self.navigator.planner.band or (here[2] - 1.0, here[2] + 1.0)
        started = time.perf_counter()
        with self.recorder.timers("planning"):
            ranked = self.frontiers.rank(
                self.occupancy, band, here, self.config.exploration.frontier_min_cells
            )
        self.navigator.planned(time.perf_counter() - started)  # charged like any route's planning
        reach = self.time_left * self.config.robot.speed
        reachable = [c for c in ranked if c.distance_m <= reach]
        self.budget_bound = len(reachable) < len(ranked)
        return reachable

    def _on_transit_frame(self, frame: Frame) -> None:
        self.ctx.integrate(frame)
        self._observe(frame)

    def _observe(self, frame: Frame) -> None:
        """Register the frame's targets (eqs 3-5) and add each registered mask's points to its
        target's coverage (000 Table 6's box, for a robot that never inspects)."""
        ctx = self.ctx
        for detection, target_id in register_targets(ctx, frame):
            with ctx.timers("perception"):
                points = detection_points(
                    frame, detection, ctx.config.mask_erosion_px, ctx.min_height
                )
            self.recorder.coverage.add_frame(target_id, frame, points)
