"""Driving the robot: routes on its own map, and sensing on the way.

:class:`Navigator` follows a route in steps, scanning with the LiDAR every ``lidar_every_m``
metres and handing a camera frame to the mission every ``camera_every_m`` (so targets are found
in transit). Before each step it re-checks the route against the map it has just updated, and
asks the local planner for a new route when the old one now crosses an obstacle.

Simulated time does not pass while a planner computes. With ``charge_planning_time`` the robot
stands still for each route's planning wall time, as a real robot waits for its planner, so a
slow planner costs mission time (the baseline comparison of 000 Sec VII-D).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import PlanningError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.missions.xflie.metrics import Timers
from seminspect.planning.gridmap import CostGrid
from seminspect.planning.protocols import RoutePlanner
from seminspect.planning.routes import LocalPlanner
from seminspect.platform.protocol import Platform
from seminspect.sensors import Frame, LidarScan

#: Metres a goal may be missed by when the robot already stands within the goal radius plus this.
ARRIVAL_SLACK = 0.05


@dataclass
class NavigationStats:
    """Counters and timings of everything the navigator planned and drove."""

    local_plans: int = 0
    local_failures: int = 0
    local_planning_s: list[float] = field(default_factory=list)
    replans: int = 0
    blocked: int = 0
    #: Wall time of every planner call of the mission (routes, graph queries, views) [s].
    planning_s: float = 0.0


class Navigator:
    """Drives a platform along routes planned on its occupancy map.

    Args:
        platform: the robot.
        occupancy: the robot's own map, updated here from LiDAR scans.
        planner: the local planner (routes may enter unknown space at a cost).
        on_frame: called with every camera frame taken while driving.
        lidar_every_m, camera_every_m: sensing intervals while driving.
        clear_misses_to: free space is cleared along LiDAR beams with no return up to this range.
        carving_spacing: thinned free-space carving of scans (cells, ``mapping.carving``);
            None carves along every beam.
        timers: where sensing, planning and driving time is charged.
        charge_planning_time: the robot waits for each route's planning wall time.
        guard_unknown: moves kept to known space (``known_only``) also keep the planner's
            clearance from unknown cells below the robot, as from occupied ones. An aerial robot
            needs this: its LiDAR sees nothing below it, and what it has not seen there (a slab,
            rubble) is what it would fly into. Space above it stays as mapped: the robot climbs
            only along a face it is looking at.
    """

    def __init__(
        self,
        platform: Platform,
        occupancy: VoxelMap,
        planner: LocalPlanner,
        on_frame: Callable[[Frame], None],
        *,
        lidar_every_m: float,
        camera_every_m: float,
        clear_misses_to: float,
        carving_spacing: float | None = None,
        timers: Timers | None = None,
        charge_planning_time: bool = False,
        guard_unknown: bool = False,
    ) -> None:
        self.timers = timers or Timers()
        self.guard_unknown = guard_unknown
        self.platform = platform
        self.charge_planning_time = charge_planning_time
        self.occupancy = occupancy
        self.planner = planner
        self.on_frame = on_frame
        self.lidar_every_m = lidar_every_m
        self.camera_every_m = camera_every_m
        self.clear_misses_to = clear_misses_to
        self.carving_spacing = carving_spacing
        self.stats = NavigationStats()
        #: The same planner kept to observed free space, for short moves beside structures.
        self.known_planner = LocalPlanner(
            dataclasses.replace(planner.model, unknown_cost=None),
            planner.mode,
            band=planner.band or (0.0, 1.0),
            heuristic_weight=planner.heuristic_weight,
        )
        self.last_scan: LidarScan | None = None
        self._since_camera = 0.0

    # ----------------------------------------------------------------- sensing
    def sense_lidar(self) -> LidarScan:
        """Scan, update the map, and keep the scan as :attr:`last_scan`."""
        with self.timers("sensing"):
            self.last_scan = self.platform.scan()
            self.occupancy.integrate_scan(
                self.last_scan,
                clear_misses_to=self.clear_misses_to,
                carving_spacing=self.carving_spacing,
            )
            if self.guard_unknown:
                self._clear_body()
        return self.last_scan

    def _clear_body(self) -> None:
        """Mark the unknown cells within the planner's clearance of the robot free: its body
        is there, and it came there by moves that kept this clearance."""
        voxel_map = self.occupancy
        reach = self.planner.model.robot_radius
        here = self.platform.position
        lo = np.maximum(voxel_map.world_to_index(here - reach), 0)
        hi = np.minimum(voxel_map.world_to_index(here + reach) + 1, voxel_map.shape)
        block = tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))
        cells = np.stack(
            np.meshgrid(*(np.arange(a, b) for a, b in zip(lo, hi, strict=True)), indexing="ij"),
            axis=-1,
        )
        near = np.linalg.norm(voxel_map.index_to_world(cells) - here, axis=-1) <= reach
        states = voxel_map.states[block]
        states[near & (states == UNKNOWN)] = FREE

    def guarded_map(self) -> VoxelMap:
        """The map as moves in known space see it: unknown cells below the robot count as
        occupied when :attr:`guard_unknown` is set (see the class docstring)."""
        if not self.guard_unknown:
            return self.occupancy
        voxel_map = self.occupancy
        below = voxel_map.world_to_index(self.platform.position)[2]
        guarded = voxel_map.states.copy()
        lower = guarded[:, :, : max(below, 0)]
        lower[lower == UNKNOWN] = OCCUPIED
        return VoxelMap(voxel_map.origin, voxel_map.resolution, guarded)

    def mark_contact(self, contact: NDArray[np.float64] | None) -> None:
        """Write a felt obstacle into the map, so that no route tries it again."""
        if contact is None:
            return
        cell = self.occupancy.world_to_index(contact)
        if self.occupancy.contains_index(cell):
            self.occupancy.states[tuple(cell)] = OCCUPIED

    def cost_grid(self, known_only: bool = False) -> CostGrid:
        """The planner's grid on the map as it is now (costs filled as they are asked for)."""
        planner = self.known_planner if known_only else self.planner
        voxel_map = self.guarded_map() if known_only else self.occupancy
        return CostGrid.build(voxel_map, planner.model, planner.band, lazy=True)

    def segment_is_free(
        self, a: ArrayLike, b: ArrayLike, grid: CostGrid | None = None, known_only: bool = False
    ) -> bool:
        """Whether the robot's map lets it drive straight from ``a`` to ``b`` (through unknown
        space too, unless ``known_only``)."""
        with self.timers("planning"):
            return (grid or self.cost_grid(known_only)).segment_is_free(a, b)

    # ----------------------------------------------------------------- driving
    def drive(
        self,
        waypoints: NDArray[np.float64],
        final_yaw: float | None = None,
        known_only: bool = False,
    ) -> bool:
        """Follow ``waypoints`` (the first is where the robot stands). False if the route became
        blocked or the robot was stopped; True when it reached the last waypoint."""
        for target in waypoints[1:]:
            if not self._drive_segment(np.asarray(target, dtype=np.float64), known_only):
                return False
        if final_yaw is not None:
            self.platform.turn_to(final_yaw)
        return True

    def _drive_segment(self, target: NDArray[np.float64], known_only: bool) -> bool:
        while True:
            here = self.platform.position
            gap = float(np.linalg.norm((target - here)[:2]))
            if gap < 1e-3 and abs(target[2] - here[2]) < 1e-3:
                return True
            if not self._clear_ahead(here, target, gap, known_only):
                self.stats.replans += 1
                return False
            step = min(gap, self.lidar_every_m) if gap > 0 else 0.0
            point = target if step == gap else here + (target - here) * (step / gap)
            heading = math.atan2(target[1] - here[1], target[0] - here[0]) if gap > 0.2 else None
            with self.timers("driving"):
                motion = self.platform.move_to(point, heading)
            self.sense_lidar()
            self._since_camera += motion.distance
            if self._since_camera >= self.camera_every_m:
                self._since_camera = 0.0
                with self.timers("sensing"):
                    frame = self.platform.capture(intensity=False)
                self.on_frame(frame)
            if motion.blocked:
                self.stats.blocked += 1
                self.mark_contact(motion.contact)
                return False

    def _clear_ahead(
        self, here: NDArray[np.float64], target: NDArray[np.float64], gap: float, known_only: bool
    ) -> bool:
        """The segment is free, or free once past the inflation margin the robot may stand in
        (after a close view; the planner starts such routes from the nearest free cell)."""
        grid = self.cost_grid(known_only)
        if self.segment_is_free(here, target, grid):
            return True
        escape = self.planner.model.robot_radius + self.occupancy.resolution
        if gap <= escape:  # stepping out of the margin to the planner's first free cell
            return self.segment_is_free(target, target, grid)
        return self.segment_is_free(here + (target - here) * (escape / gap), target, grid)

    def go_to(
        self,
        goal: ArrayLike,
        radius: float,
        *,
        final_yaw: float | None = None,
        attempts: int = 5,
        known_only: bool = False,
        planner: RoutePlanner | None = None,
    ) -> bool:
        """Plan and drive to within ``radius`` of ``goal``, replanning as the map grows; with
        ``known_only`` the route stays in observed free space. ``planner`` replaces the local
        planner (e.g. by the volumetric baseline)."""
        if planner is None:
            planner = self.known_planner if known_only else self.planner
        goal_point = np.asarray(goal, dtype=np.float64)
        for _ in range(attempts):
            if self._arrived(goal_point, radius):
                break
            self.stats.local_plans += 1
            started = time.perf_counter()
            try:
                with self.timers("planning"):
                    voxel_map = self.guarded_map() if known_only else self.occupancy
                    path = planner.plan(voxel_map, self.platform.position, goal_point, radius)
            except PlanningError:
                self.stats.local_failures += 1
                self.planned(time.perf_counter() - started)
                return False
            self.stats.local_planning_s.append(path.planning_time)
            self.planned(path.planning_time)
            if self.drive(path.waypoints, known_only=known_only):
                break
        arrived = self._arrived(goal_point, radius)
        if arrived and final_yaw is not None:
            self.platform.turn_to(final_yaw)
        return arrived

    def planned(self, seconds: float) -> None:
        """Account ``seconds`` of planning wall time; the robot waits for it when charged."""
        self.stats.planning_s += seconds
        if self.charge_planning_time:
            self.platform.wait(seconds)

    def _arrived(self, goal: NDArray[np.float64], radius: float) -> bool:
        here = self.platform.position
        horizontal = float(np.linalg.norm((goal - here)[:2]))
        if self.planner.mode == "ground":
            return horizontal <= radius + ARRIVAL_SLACK
        return float(np.linalg.norm(goal - here)) <= radius + ARRIVAL_SLACK
