"""Surface tracking and view steps: how the robot moves around a target during a level.

What the robot keeps its distance from is the target's points in view together with every
LiDAR return attached to what it has seen of the target (so parts out of the camera's view,
and debris beside it, count too). FLIE's local view planner (002 eqs 1-2) gives the next view
pose along that surface; blocked steps are retried shorter, then closer to the surface.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from seminspect.core.errors import PlanningError
from seminspect.graphs.lsg.model import TargetNode
from seminspect.mapping.voxel import OCCUPIED
from seminspect.missions.xflie.context import MissionContext
from seminspect.planning.view_planner import ViewConstraints, next_view_pose

#: Voxel size of the cloud kept of the target under inspection [m].
TARGET_VOXEL = 0.2
#: LiDAR returns closer than this to the target's cloud belong to it or stand beside it [m].
ATTACHED = 1.5
#: Fractions of the full view-planner step tried, in order, when a step is blocked.
STEP_SCALES = (1.0, 0.5, 0.25)
#: Fractions of the viewing distance tried, in order, when no step is free at the full one.
VIEW_DISTANCE_SCALES = (1.0, 0.75)
#: A view move shorter than this does not count as a step along the surface [m].
MIN_VIEW_STEP = 0.1
#: Aerial robots keep their distance from mapped structure within this many viewing distances.
MAPPED_REACH = 1.5


class PointSet:
    """Points thinned to one per voxel (the first seen in it), with radius queries."""

    def __init__(self, voxel: float) -> None:
        self.voxel = voxel
        self.points: NDArray[np.float64] = np.empty((0, 3))
        self._voxels: set[tuple[int, ...]] = set()
        self._tree: cKDTree | None = None

    @property
    def size(self) -> int:
        return len(self.points)

    def add(self, points: NDArray[np.float64]) -> None:
        """Keep each point whose voxel holds none yet, in order. Only the new points are
        sorted: deduplicating the whole, growing set on every view cost seconds a mission."""
        cells = np.floor(points / self.voxel).astype(np.int64)
        fresh = []
        for index in first_of_each_row(cells).tolist():
            cell = tuple(cells[index].tolist())
            if cell not in self._voxels:
                self._voxels.add(cell)
                fresh.append(index)
        if fresh:
            self.points = np.vstack([self.points, points[fresh]])
            self._tree = None

    def near(self, points: NDArray[np.float64], radius: float) -> NDArray[np.bool_]:
        """Which ``points`` lie within ``radius`` of the set.

        Only points inside the set's bounding box grown by ``radius`` (and a hair, against
        rounding) can be, so only those are looked up in the tree: a scan's returns are mostly
        far from the target.
        """
        if self._tree is None:
            self._tree = cKDTree(self.points)
        reach = radius * (1 + 1e-9) + 1e-9
        lower, upper = self._tree.mins - reach, self._tree.maxes + reach
        candidates = np.flatnonzero(np.all((points >= lower) & (points <= upper), axis=1))
        found = np.zeros(len(points), dtype=bool)
        distance, _ = self._tree.query(points[candidates], distance_upper_bound=radius)
        found[candidates] = np.isfinite(distance)
        return found


def first_of_each_row(cells: NDArray[np.int64]) -> NDArray[np.intp]:
    """Index of the first occurrence of each distinct row of ``cells`` (``(N, 3)``), ascending.

    The same as ``np.sort(np.unique(cells, axis=0, return_index=True)[1])``, about ten times
    faster: each row becomes one integer key within the rows' bounding box, and sorting keys
    is cheaper than sorting rows. The box must hold fewer cells than ``intp`` counts (true of
    any voxels of a world; numpy raises otherwise).
    """
    if not len(cells):
        return np.empty(0, dtype=np.intp)
    offset = cells - cells.min(axis=0)
    keys = np.ravel_multi_index(tuple(offset.T), tuple(offset.max(axis=0) + 1))
    _, first = np.unique(keys, return_index=True)
    return np.sort(first)


class SurfaceTracker:
    """The surface of the target under inspection, and steps along it (002 eqs 1-2).

    Args:
        ctx: the mission's shared state.
        view: the view planner's constraints (viewing distance, overlaps, fields of view).
    """

    def __init__(self, ctx: MissionContext, view: ViewConstraints) -> None:
        self.ctx = ctx
        self.view = view
        #: Everything seen of the target under inspection, thinned to ``TARGET_VOXEL``.
        self.target_cloud = PointSet(TARGET_VOXEL)

    def start_target(self) -> None:
        """Forget the previous target's cloud."""
        self.target_cloud = PointSet(TARGET_VOXEL)

    def surface(self, mask_points: NDArray[np.float64]) -> NDArray[np.float64]:
        """What the view planner steps along: the target's points in view, and every LiDAR
        return attached to the target (within ``ATTACHED`` of anything seen of it), so that
        parts of it out of the camera's view and debris beside it are kept at a distance too.
        Aerial robots add the structure of their map around them (see :meth:`mapped_nearby`)."""
        parts = [mask_points]
        scan = self.ctx.navigator.last_scan
        if scan is not None and self.target_cloud.size:
            returns = scan.points[scan.points[:, 2] >= self.ctx.min_height]
            parts.append(returns[self.target_cloud.near(returns, ATTACHED)])
        if self.ctx.config.mode == "aerial":
            parts.append(self.mapped_nearby())
        return np.vstack(parts)

    def mapped_nearby(self) -> NDArray[np.float64]:
        """Centres of the occupied cells of the robot's map within ``MAPPED_REACH`` viewing
        distances of it, the ground left out. A flying robot passes over what lies below its
        camera's view (a wall stub, a fallen slab, rubble); its map still holds what any earlier
        view or scan saw of them, and the view planner must keep its distance from them too."""
        voxel_map = self.ctx.occupancy
        here = self.ctx.platform.position
        reach = MAPPED_REACH * self.view.d_view
        lo = np.maximum(voxel_map.world_to_index(here - reach), 0)
        hi = np.minimum(voxel_map.world_to_index(here + reach) + 1, voxel_map.shape)
        lo[2] = max(lo[2], voxel_map.world_to_index([0, 0, self.ground_top])[2] + 1)
        block = voxel_map.states[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]]
        cells = np.argwhere(block == OCCUPIED) + lo
        centres = voxel_map.index_to_world(cells)
        near = np.linalg.norm((centres - here)[:, :2], axis=1) <= reach
        return centres[near]

    @property
    def ground_top(self) -> float:
        """Height of the highest map cell that may hold the ground [m]."""
        return self.ctx.min_height + self.ctx.occupancy.resolution

    def step_along(self, surface: NDArray[np.float64], target: TargetNode) -> bool:
        """Move to the next view pose of 002 eqs (1)-(2); False when no step is possible.

        When the full step is blocked, shorter steps along the surface are tried, and then the
        same steps from closer to the surface (where the space around the target is too tight
        for the viewing distance, as beside a car in a tunnel), before giving up.
        """
        ctx = self.ctx
        points = self.in_view(surface) if len(surface) else target.position[None, :]
        for closer, scale in itertools.product(VIEW_DISTANCE_SCALES, STEP_SCALES):
            overlap = 1.0 - (1.0 - self.view.overlap_h) * scale
            view = self.view.model_copy(
                update={"overlap_h": overlap, "d_view": self.view.d_view * closer}
            )
            with ctx.timers("planning"):
                started = time.perf_counter()
                try:
                    pose = next_view_pose(ctx.platform.position, points, view)
                except PlanningError:
                    return False
                finally:
                    ctx.navigator.planned(time.perf_counter() - started)
            if self.move_to_view(pose.position, pose.yaw):
                return True
        return False

    def in_view(self, surface: NDArray[np.float64]) -> NDArray[np.float64]:
        """The surface up to the top of the view: parts above it do not limit the level, while
        anything below the robot (a collapsed slab, rubble) must keep its distance too."""
        reach = math.tan(math.radians(self.view.vfov_deg) / 2) * self.view.d_view
        below = surface[surface[:, 2] <= self.ctx.platform.position[2] + reach]
        return below if len(below) else surface

    def move_to_view(self, goal: NDArray[np.float64], yaw: float) -> bool:
        """A short move beside the structure. Aerial robots keep to space they have seen to be
        free: below and beside a flying robot lies what its sensors see least."""
        ctx = self.ctx
        platform, navigator = ctx.platform, ctx.navigator
        known_only = ctx.config.mode == "aerial"
        if ctx.config.mode == "ground":
            goal = np.array([goal[0], goal[1], platform.position[2]])
        step = float(np.linalg.norm(goal - platform.position))
        if step < MIN_VIEW_STEP:
            return False
        if navigator.segment_is_free(platform.position, goal, known_only=known_only):
            with ctx.timers("driving"):
                motion = platform.move_to(goal, yaw)
            navigator.mark_contact(motion.contact)
            navigator.sense_lidar()
            if motion.reached:
                return True
        return navigator.go_to(
            goal, radius=min(0.5, 0.25 * step), final_yaw=yaw, attempts=2, known_only=known_only
        )
