"""The mission's local planner: obstacle-aware routes on the robot's own, growing map.

During a mission the robot's occupancy map is partly unknown and changes after every scan, so
nothing can be precomputed across queries. This planner evaluates cell costs lazily (only the
cells the search touches are inflated, see :mod:`~seminspect.planning.gridmap`), lets the route
enter unknown space at an extra cost so the robot can head into unexplored areas, and returns a
short list of waypoints: the grid route with collinear points removed and straight-line
shortcuts taken wherever the map allows.

Ground robots plan on a height band: a column is blocked when any voxel of the band is occupied.
Aerial robots plan in 3D.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Literal

from numpy.typing import ArrayLike

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.grid_astar import GridPath, make_query, search
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.smoothing import path_length, refine_path

Mode = Literal["ground", "aerial"]

#: Height band a ground robot's body sweeps [m]: above small bumps, up to its sensor mast.
DEFAULT_GROUND_BAND = (0.3, 1.5)


class LocalPlanner:
    """Plans on whatever map it is handed, query by query.

    Args:
        model: inflation, risk and unknown-space cost; give ``unknown_cost`` a number (e.g. 1.0)
            to let routes cross unexplored space, ``None`` to keep them on known free space.
        mode: ``"ground"`` (8-connected on ``band``) or ``"aerial"`` (26-connected in 3D).
        band: the ground robot's height band ``(z_low, z_high)`` in map coordinates [m].
        start_tolerance: a start that is blocked (closer to a wall than the robot radius, as
            happens after a close inspection view) begins from the nearest traversable cell
            within this distance; defaults to the robot radius.
        heuristic_weight: weighted A*: the grid route costs at most this many times the optimum.
            Unknown space makes the plain heuristic weak (it assumes cost 1 where crossing costs
            ``1 + unknown_cost``); a weight near that ratio cuts expansions by orders of magnitude,
            and shortcutting removes most of the detour (``bench/grid_planning.py`` measures
            both). 1 gives optimal routes.
    """

    def __init__(
        self,
        model: CostModel,
        mode: Mode = "aerial",
        band: tuple[float, float] = DEFAULT_GROUND_BAND,
        start_tolerance: float | None = None,
        heuristic_weight: float = 2.0,
    ) -> None:
        if mode not in ("ground", "aerial"):
            raise InvalidInputError(f"mode must be 'ground' or 'aerial', got {mode!r}")
        if not (math.isfinite(heuristic_weight) and heuristic_weight >= 1):
            raise InvalidInputError(f"heuristic_weight must be >= 1, got {heuristic_weight!r}")
        self.heuristic_weight = float(heuristic_weight)
        self.model = model
        self.mode = mode
        self.band = band if mode == "ground" else None
        self.start_tolerance = model.robot_radius if start_tolerance is None else start_tolerance

    def plan(
        self,
        voxel_map: VoxelMap,
        start: ArrayLike,
        goal: ArrayLike,
        goal_radius: float = 0.0,
    ) -> GridPath:
        """A simplified route on the current ``voxel_map``.

        The returned path's ``waypoints`` and ``length`` are those of the simplified route;
        ``cells`` and ``cost`` those of the optimal grid route it came from. Ground routes keep
        the start's height.

        Raises:
            PlanningError: start or goal outside the map or blocked, or no route exists.
        """
        t0 = time.perf_counter()
        grid = CostGrid.build(voxel_map, self.model, self.band, lazy=True)
        query = make_query(grid, start, goal, goal_radius, self.start_tolerance)
        raw = search(grid, query, self.heuristic_weight, started=t0)
        refined = refine_path(raw.waypoints, grid).waypoints
        return dataclasses.replace(
            raw,
            waypoints=refined,
            length=path_length(refined),
            planning_time=time.perf_counter() - t0,
            engine=f"local-{self.mode}",
        )


def warm_up() -> float:
    """Compile the local planner's kernels, or load them from numba's on-disk cache, on a tiny
    map with a wall and unknown space, in both modes; returns the seconds it took.

    A mission calls this before its clock starts, so that on a fresh install (no cache yet) its
    first routes time the search rather than the compiler.
    """
    started = time.perf_counter()
    voxel_map = VoxelMap.empty((0.0, 0.0, 0.0), (4.0, 4.0, 2.0), 0.25)
    voxel_map.states[:, :, :4] = FREE
    voxel_map.states[8, :12, :] = OCCUPIED
    for unknown_cost in (1.0, None):
        model = CostModel(0.3, risk_radius=0.3, unknown_cost=unknown_cost)
        for mode in ("ground", "aerial"):
            planner = LocalPlanner(model, mode, band=(0.2, 0.8))
            planner.plan(voxel_map, (0.5, 0.5, 0.5), (3.5, 0.5, 0.5), goal_radius=0.2)
    return time.perf_counter() - started
