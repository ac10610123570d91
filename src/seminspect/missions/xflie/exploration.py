"""Exploration: ``π^expl:360`` surveys on the spot, and hops to frontiers of the robot's map.

A survey turns the robot through a full circle in steps of the camera's field of view (less
the configured overlap) and registers every frame's target detections (eqs 3-5). When no
uninspected target is left, the robot drives to the nearest frontier between known free and
unknown space and surveys there; frontiers it visited, or tried and could not reach, are
remembered and not chosen again. Aerial robots fly there level, at their height, as between
targets (``approach.level_flight_planner``).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from seminspect.missions.xflie.approach import level_flight_planner
from seminspect.missions.xflie.config import survey_headings
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.sightings import register_targets
from seminspect.planning.frontier import find_frontiers
from seminspect.sensors import Frame

#: Frontiers nearer than this to the robot (or to one already visited) are not worth a trip [m].
FRONTIER_MIN_DISTANCE = 3.0
#: How many of the nearest frontiers are tried before exploration gives up.
FRONTIER_TRIES = 5
#: How close the robot must come to a frontier's goal [m].
FRONTIER_RADIUS = 1.5


class Exploration:
    """Surveys and frontier hops, with the memory of frontiers already spent.

    ``on_frame`` takes each survey frame (default: register its targets, eqs 3-5).
    """

    def __init__(
        self, ctx: MissionContext, on_frame: Callable[[Frame], object] | None = None
    ) -> None:
        self.ctx = ctx
        self.on_frame = on_frame or (lambda frame: register_targets(ctx, frame))
        #: Goals of frontiers visited or found unreachable.
        self.spent_frontiers: list[NDArray[np.float64]] = []

    def survey(self) -> None:
        """``π^expl:360``: turn on the spot, registering every frame's detections."""
        ctx = self.ctx
        count = survey_headings(ctx.params.fov_deg, ctx.config.exploration.survey_overlap)
        start = ctx.platform.yaw
        for k in range(count):
            if ctx.time_left <= 0:
                return
            ctx.platform.turn_to(start + k * 2.0 * math.pi / count)
            self.on_frame(ctx.capture())
        ctx.on_step()

    def explore(self, keep: Callable[[NDArray[np.float64]], bool] | None = None) -> bool:
        """Drive to the nearest reachable frontier and survey there; False if none is left.

        Frontiers within ``FRONTIER_MIN_DISTANCE`` of the robot are skipped: they are the ring
        of ground around its own body that no sensor sees, which no trip resolves. A frontier
        visited or found unreachable is not chosen again. ``keep`` (default: every frontier)
        says which frontier goals this robot may choose at all (another robot's are not).
        """
        ctx = self.ctx
        here = ctx.platform.position
        band = ctx.navigator.planner.band or (here[2] - 1.0, here[2] + 1.0)
        frontiers = find_frontiers(
            ctx.occupancy, band, ctx.config.exploration.frontier_min_cells, here[2]
        )

        def distance(goal: NDArray[np.float64]) -> float:
            return float(np.linalg.norm((goal - here)[:2]))

        candidates = [
            f
            for f in frontiers
            if distance(f.goal) >= FRONTIER_MIN_DISTANCE
            and not self.is_spent(f.goal)
            and (keep is None or keep(f.goal))
        ]
        candidates.sort(key=lambda f: distance(f.goal))
        planner = None
        if ctx.config.mode == "aerial":  # goals lie at its height: no route over the roofs
            planner = level_flight_planner(ctx.navigator.planner, here[2])
        for frontier in candidates[:FRONTIER_TRIES]:
            self.spent_frontiers.append(frontier.goal)
            if ctx.navigator.go_to(frontier.goal, radius=FRONTIER_RADIUS, planner=planner):
                ctx.event("frontier", goal=frontier.goal.round(2).tolist(), cells=frontier.cells)
                self.survey()
                return True
        return False

    def is_spent(self, goal: NDArray[np.float64]) -> bool:
        """Whether a frontier near ``goal`` was visited or tried already."""
        return any(
            np.linalg.norm((goal - f)[:2]) < FRONTIER_MIN_DISTANCE for f in self.spent_frontiers
        )
