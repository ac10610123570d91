"""Target links: ``v_I - v_I`` edges from a newly inspected target to its inspected neighbours.

Each edge is realised by a route through the robot's known free space between the two
targets' entry levels (the first route any of a list of planners finds), so that the
hierarchical planner can later follow the Target layer without re-planning in the unknown.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import PlanningError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode, TargetStatus
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie.context import MissionContext
from seminspect.planning.grid_astar import GridPath
from seminspect.planning.gridmap import CostModel
from seminspect.planning.routes import LocalPlanner

#: A new target is linked to at most this many inspected targets, nearest first.
NEIGHBOURS = 3
#: Height band of the link planners when the robot's planner has none [m].
DEFAULT_BAND = (0.3, 1.5)


class TargetLinks:
    """Links each inspected target to its nearest inspected neighbours.

    Args:
        ctx: the mission's shared state.
        local: the robot's local planner (its clearance, mode and band are reused).
    """

    def __init__(self, ctx: MissionContext, local: LocalPlanner) -> None:
        self.ctx = ctx
        self.local = local

    def connect(self, target: TargetNode) -> None:
        """``v_I - v_I`` edges to the nearest inspected targets, through known free space.

        The robot does not drive these routes now, so they keep half a cell diagonal more
        clearance than its routes where they can: the planner measures between cell centres,
        and a straight segment may pass anywhere within the cells it crosses. Where no route
        keeps it, the robot's own clearance is used, so the Target layer stays as connected.
        """
        ctx = self.ctx
        graph = ctx.graph
        entry = LayeredSemanticGraph.entry_level(target).position
        planners = self.link_planners()
        for other in self.neighbours(target, entry):
            start = LayeredSemanticGraph.entry_level(other).position
            with ctx.timers("planning"):
                started = time.perf_counter()
                path = first_route(planners, ctx.occupancy, start, entry)
                ctx.navigator.planned(time.perf_counter() - started)
            if path is None:
                continue
            via = path.waypoints[1:-1]
            with ctx.timers("graph"):
                graph.connect_targets(other.id, target.id, via if len(via) else None)

    def neighbours(self, target: TargetNode, entry: NDArray[np.float64]) -> list[TargetNode]:
        """The inspected targets whose entry levels lie nearest ``entry``, nearest first."""
        inspected = [t for t in self.ctx.graph.targets(TargetStatus.INSPECTED) if t is not target]
        inspected.sort(
            key=lambda t: float(
                np.linalg.norm(LayeredSemanticGraph.entry_level(t).position - entry)
            )
        )
        return inspected[:NEIGHBOURS]

    def link_planners(self) -> list[LocalPlanner]:
        """Known-space planners with half a cell diagonal of extra clearance, then none."""
        local = self.local
        dims = 2 if local.mode == "ground" else 3
        slack = 0.5 * self.ctx.occupancy.resolution * math.sqrt(dims)
        return [
            LocalPlanner(
                CostModel(local.model.robot_radius + extra, 0.0, unknown_cost=None),
                local.mode,
                band=local.band or DEFAULT_BAND,
            )
            for extra in (slack, 0.0)
        ]


def first_route(
    planners: Iterable[LocalPlanner],
    occupancy: VoxelMap,
    start: NDArray[np.float64],
    goal: NDArray[np.float64],
) -> GridPath | None:
    """The route of the first planner that finds one, if any."""
    for planner in planners:
        try:
            return planner.plan(occupancy, start, goal)
        except PlanningError:
            continue
    return None
