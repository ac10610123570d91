"""The approach to a selected target: route there, then confirm it is really there.

The route has two parts. The known part runs over the 3DLSG with the hierarchical planner, to
the traversable node nearest the goal (when the graph gets the robot closer than driving
straight); the rest is planned on the robot's own occupancy map into unknown space, to within
``ε`` of the target (eq 2's proximity condition). With ``planner="volumetric"`` (000 Sec VII-D's
baseline) the volumetric planner plans the whole way instead.

Aerial robots travel between targets at the height they fly (level with the robot, on a band of
the map, so a route cannot climb over a roof to meet ``ε`` from above; a graph leg only to a
node at that height, as their graph holds every level's poses), and leave an inspected
target the way they climbed it (:meth:`Approach.descend`): every target's ``Level-0`` then
starts at the first level's height, as the first target's does.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import PlanningError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode, TargetStatus
from seminspect.missions.xflie.config import ResolvedMissionConfig
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.sightings import register_targets, target_view
from seminspect.planning.gridmap import CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.protocols import RoutePlanner
from seminspect.planning.routes import LocalPlanner
from seminspect.planning.smoothing import refine_path
from seminspect.planning.volumetric import RebuildingVolumetricPlanner
from seminspect.platform.protocol import heading_to

#: Extra clearance added to the robot radius in the planners' inflation [m].
PLANNING_MARGIN = 0.2
#: The same for aerial robots [m]. A flying robot's clearance is measured in 3D between the
#: centres of 0.3 m voxels, which can lie up to half a cell diagonal (0.26 m) beyond the surface
#: they hold; the simulator's collision field is itself conservative (a lower bound that may
#: understate the distance to a surface by 0.69 m in the 0.2 m grid of the collapsed-building
#: sites, ``worlds/collision.py``). A 0.2 m margin let the robot graze a leaning slab it had
#: mapped correctly; 0.8 m keeps every motion clear of both.
AERIAL_PLANNING_MARGIN = 0.8
#: Risk band of the local planner's cost model [m].
LOCAL_RISK_RADIUS = 0.3
#: The volumetric baseline's map resolution and risk band (000 Sec VII-D: D*+ on M_0.4, risk
#: parameter 0.2) [m].
BASELINE_RESOLUTION = 0.4
BASELINE_RISK_RADIUS = 0.2
#: Extra arrival radii tried, beyond ``ε``, when the robot cannot come within ``ε`` [m].
ARRIVAL_FALLBACKS = (0.0, 1.0, 2.5)
#: Headings tried when confirming a target: straight at it, then either side [rad].
CONFIRM_OFFSETS = (0.0, math.radians(35), -math.radians(35))
#: The graph leg is skipped unless it ends this much closer to the goal than the robot is [m].
GRAPH_LEG_GAIN = 5.0
#: Heights this close count as one flight level [m]: an aerial robot higher than its target's
#: ``Level-0`` by more flies back down to it, and takes no graph leg to a node off its level.
FLIGHT_LEVEL_TOLERANCE = 0.5


class Approach:
    """Reaching a target and confirming it on arrival.

    Args:
        ctx: the mission's shared state.
        planner: the hierarchical planner over the mission's graph.
        baseline: the volumetric baseline planner, when it replaces the local planner.
    """

    def __init__(
        self,
        ctx: MissionContext,
        planner: HierarchicalPlanner,
        baseline: RoutePlanner | None = None,
    ) -> None:
        self.ctx = ctx
        self.planner = planner
        self.baseline = baseline

    def reach(self, target: TargetNode) -> bool:
        """Navigate to within ``ε`` of a detected target (eq 2's proximity condition)."""
        ctx = self.ctx
        goal = target.position
        ctx.event("selected", target=target.id, utility=round(target.utility, 4))
        planner = self.baseline
        if ctx.config.mode == "aerial" and planner is None:
            goal = np.array([goal[0], goal[1], ctx.platform.position[2]])
            planner = level_flight_planner(ctx.navigator.planner, goal[2])
        self.graph_leg(goal)
        for extra in ARRIVAL_FALLBACKS:
            radius = ctx.params.epsilon + extra
            if ctx.navigator.go_to(goal, radius, planner=planner):
                ctx.event("arrived", target=target.id)
                return True
            if ctx.time_left <= 0:
                return False
        return False

    def confirm(self, target: TargetNode) -> bool:
        """Look for the target from where the robot arrived: straight at it, then either side.

        A detection that is not there when the robot comes to look (a false positive of the
        segmentation, or a badly localised one) is discarded rather than inspected.
        """
        ctx = self.ctx
        facing = heading_to(ctx.platform.position, target.position)
        for offset in CONFIRM_OFFSETS:
            ctx.platform.turn_to(facing + offset)
            frame = ctx.capture()
            register_targets(ctx, frame)
            if target.id not in ctx.graph:  # merged away by eq (4) after a better view
                return False
            _, points = target_view(ctx, frame, target, ctx.params.d_check_T)
            if len(points):
                ctx.platform.turn_to(facing)
                return True
        return False

    def descend(self, target: TargetNode) -> None:
        """Fly an inspected target's Level and Pose graphs back to its ``Level-0``.

        The route runs through the view poses the robot flew and the climbs between levels
        (each level's ``via``), all space the robot has been in, and is driven as planned, not
        shortened: a shortcut would cross space below the robot that it has not seen.
        """
        ctx = self.ctx
        entry = LayeredSemanticGraph.entry_level(target)
        if ctx.platform.position[2] - entry.position[2] < FLIGHT_LEVEL_TOLERANCE:
            return
        with ctx.timers("planning"):
            try:
                plan = self.planner.plan(entry.id, ctx.platform.position)
            except PlanningError:  # no route in the graph: travel on from where it is
                return
        ctx.recorder.plan(entry.id, plan)
        ctx.navigator.planned(plan.timing.total_s)
        descended = ctx.navigator.drive(plan.waypoints)
        ctx.event(
            "descended",
            target=target.id,
            reached=descended,
            height=round(float(ctx.platform.position[2]), 2),
        )

    def on_flight_level(self, point: NDArray[np.float64]) -> bool:
        """Whether ``point`` lies at the height an aerial robot flies (ground robots: always)."""
        ctx = self.ctx
        height = abs(point[2] - ctx.platform.position[2])
        return ctx.config.mode != "aerial" or height <= FLIGHT_LEVEL_TOLERANCE

    def graph_leg(self, goal: NDArray[np.float64]) -> None:
        """The known part of the route: over the 3DLSG to the traversable node nearest ``goal``."""
        ctx = self.ctx
        if not ctx.graph.targets(TargetStatus.INSPECTED) or ctx.config.planner != "hierarchical":
            return
        with ctx.timers("planning"):
            entry = self.planner.nearest_entry(goal)
            entry_position = ctx.graph.node(entry).position
            here = ctx.platform.position
            if np.linalg.norm((goal - entry_position)[:2]) + GRAPH_LEG_GAIN >= np.linalg.norm(
                (goal - here)[:2]
            ):
                return  # the graph gets the robot no closer than driving straight for it
            if not self.on_flight_level(entry_position):
                return  # an aerial robot's graph holds every level's poses: it travels level
            try:
                plan = self.planner.plan(entry, here)
            except PlanningError:  # the Target layer does not join the two; drive without it
                return
            ctx.recorder.plan(entry, plan)
            refined = refine_path(plan.waypoints, ctx.navigator.cost_grid())
            ctx.navigator.planned(plan.timing.total_s + refined.refine_time)
            route = refined.waypoints
        ctx.navigator.drive(route)


def planning_clearance(config: ResolvedMissionConfig) -> float:
    """The distance the planners keep between the robot's centre and mapped structure [m]."""
    margin = AERIAL_PLANNING_MARGIN if config.mode == "aerial" else PLANNING_MARGIN
    return config.robot.radius + margin


def local_planner(config: ResolvedMissionConfig) -> LocalPlanner:
    """The robot's planner on its own map: routes may enter unknown space at a cost."""
    clearance = planning_clearance(config)
    model = CostModel(clearance, risk_radius=LOCAL_RISK_RADIUS, unknown_cost=1.0)
    return LocalPlanner(model, config.mode, band=config.robot.planning_band())


def level_flight_planner(local: LocalPlanner, height: float) -> LocalPlanner:
    """The aerial planner kept level at ``height``: routes on the band of the map within the
    robot's clearance above and below it."""
    clearance = local.model.robot_radius
    return LocalPlanner(
        local.model,
        "ground",
        band=(height - clearance, height + clearance),
        heuristic_weight=local.heuristic_weight,
    )


def baseline_planner(config: ResolvedMissionConfig) -> RebuildingVolumetricPlanner | None:
    """000 Sec VII-D's volumetric baseline, when the mission uses it (``planner="volumetric"``)."""
    if config.planner != "volumetric":
        return None
    clearance = planning_clearance(config)
    return RebuildingVolumetricPlanner(
        CostModel(clearance, risk_radius=BASELINE_RISK_RADIUS, unknown_cost=1.0),
        config.robot.planning_band() if config.mode == "ground" else None,
        resolution=BASELINE_RESOLUTION,
    )
