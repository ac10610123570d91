"""A sampling-based peer from OMPL: RRT-Connect plus path simplification on our occupancy check.

A second, external baseline for the volumetric comparison (issue 5): OMPL's RRT-Connect grows two
trees through the same :class:`~seminspect.planning.gridmap.CostGrid` the grid planners search (a
state is valid when its cell is traversable, a motion when the compiled voxel walk finds only
traversable cells), then ``PathSimplifier.simplifyMax`` shortens the route. It ignores the risk
and unknown-space costs: it answers "is there a collision-free path", not "the cheapest one".

OMPL is an optional extra (``pip install 'seminspect[ompl]'``); it is imported when a planner is
made, and its absence is reported as a :class:`~seminspect.core.errors.SeminspectError`.
"""

from __future__ import annotations

import functools
import time
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError, SeminspectError
from seminspect.core.rng import make_rng
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.grid_astar import GridPath, make_query
from seminspect.planning.gridmap import CostGrid, CostModel, format_point
from seminspect.planning.smoothing import path_length


def _import_ompl() -> tuple[ModuleType, ModuleType, ModuleType]:
    try:
        from ompl import base, geometric, util  # noqa: PLC0415 - an optional extra
    except ImportError:
        raise SeminspectError(
            "the OMPL planner needs the 'ompl' extra: pip install 'seminspect[ompl]'"
        ) from None
    return base, geometric, util


class OmplPlanner:
    """RRT-Connect on a voxel map, deterministic for a given ``seed``.

    Args:
        voxel_map: the occupancy map.
        model: inflation and unknown-space settings (only whether a cell is blocked matters).
        band: ``(z_low, z_high)`` plans in x-y for a ground robot on that height band.
        seed: seed of OMPL's random generator for each query.
        time_limit: seconds RRT-Connect may search before the query fails.

    Attributes:
        grid: the prepared :class:`CostGrid` (its blocked cells are what is checked).
        build_time: seconds spent preparing the map.
    """

    def __init__(
        self,
        voxel_map: VoxelMap,
        model: CostModel,
        band: tuple[float, float] | None = None,
        seed: int = 0,
        time_limit: float = 10.0,
    ) -> None:
        self._ob, self._og, self._ou = _import_ompl()
        if not time_limit > 0:
            raise InvalidInputError(f"time_limit must be > 0 s, got {time_limit!r}")
        self._ompl_seed = int(make_rng(seed, "planning", "ompl").integers(1, 2**31))
        t0 = time.perf_counter()
        self.grid = CostGrid.build(voxel_map, model, band)
        self.build_time = time.perf_counter() - t0
        self.time_limit = time_limit
        self._dims = 2 if self.grid.planar else 3

    def _space(self) -> Any:
        ob = self._ob
        space = ob.RealVectorStateSpace(self._dims)
        bounds = ob.RealVectorBounds(self._dims)
        upper = self.grid.origin + self.grid.resolution * np.asarray(self.grid.shape)
        for axis in range(self._dims):
            bounds.setLow(axis, float(self.grid.origin[axis]))
            bounds.setHigh(axis, float(upper[axis]) - 1e-6)
        space.setBounds(bounds)
        return space

    def _state(self, space: Any, point: NDArray[np.float64]) -> Any:
        state = space.allocState()
        for axis in range(self._dims):
            state[axis] = float(point[axis])
        return state

    def plan(self, start: ArrayLike, goal: ArrayLike, goal_radius: float = 0.0) -> GridPath:
        """A simplified collision-free path; ``cost`` is its length, ``expansions`` tree size.

        Raises:
            PlanningError: start or goal invalid, or no path found within ``time_limit``.
        """
        t0 = time.perf_counter()
        ob, og, ou = self._ob, self._og, self._ou
        query = make_query(self.grid, start, goal, goal_radius)
        z = float(query.start[2])
        # OMPL warns that re-seeding after the first draw is not deterministic; for a
        # single-threaded planner made after the call it is (tests check this).
        ou.setLogLevel(ou.LOG_NONE)
        ou.RNG.setSeed(self._ompl_seed)
        ou.setLogLevel(ou.LOG_WARN)
        space = self._space()
        info = ob.SpaceInformation(space)
        info.setStateValidityChecker(self._is_valid)
        info.setMotionValidator(_motion_validator_class(ob)(info, self))
        info.setup()
        setup = og.SimpleSetup(info)
        setup.setStartState(self._state(space, query.start))
        goals = ob.GoalStates(info)
        if goal_radius == 0:
            goals.addState(self._state(space, query.goal))
        else:
            for point in self.grid.centres(query.goal_cells, z):
                goals.addState(self._state(space, point))
        setup.setGoal(goals)
        planner = og.RRTConnect(info)
        setup.setPlanner(planner)
        solved = setup.solve(self.time_limit)
        if not setup.haveExactSolutionPath():
            raise PlanningError(
                f"RRT-Connect found no path from {format_point(query.start)} to "
                f"{format_point(query.goal)} within {self.time_limit:g} s ({solved})"
            )
        path = setup.getSolutionPath()
        og.PathSimplifier(info).simplifyMax(path)
        waypoints = self._waypoints(path, z)
        data = ob.PlannerData(info)
        planner.getPlannerData(data)
        length = path_length(waypoints)
        return GridPath(
            waypoints=waypoints,
            length=length,
            cost=length,
            expansions=int(data.numVertices()),
            planning_time=time.perf_counter() - t0,
            engine="ompl-rrtconnect",
            cells=np.empty((0, 3), dtype=np.int64),
        )

    def _waypoints(self, path: Any, z: float) -> NDArray[np.float64]:
        points = np.full((path.getStateCount(), 3), z)
        for n in range(path.getStateCount()):
            state = path.getState(n)
            points[n, : self._dims] = [state[axis] for axis in range(self._dims)]
        return points

    def _point(self, state: Any) -> NDArray[np.float64]:
        point = np.zeros(3)  # planar grids ignore z
        for axis in range(self._dims):
            point[axis] = state[axis]
        return point

    def _is_valid(self, state: Any) -> bool:
        point = self._point(state)
        cell = np.floor((point - self.grid.origin) / self.grid.resolution).astype(np.int64)
        if self.grid.planar:
            cell[2] = 0
        if np.any(cell < 0) or np.any(cell >= np.asarray(self.grid.shape)):
            return False
        return bool(np.isfinite(self.grid.costs_of(cell)))

    def _motion_is_free(self, a: Any, b: Any) -> bool:
        return self.grid.segment_is_free(self._point(a), self._point(b))


@functools.cache
def _motion_validator_class(ob: ModuleType) -> type:
    """OMPL's ``MotionValidator`` interface backed by the compiled voxel walk (made on first use,
    since OMPL is imported lazily)."""

    class GridMotionValidator(ob.MotionValidator):  # type: ignore[name-defined,misc]
        def __init__(self, info: Any, planner: OmplPlanner) -> None:
            super().__init__(info)
            self._planner = planner

        def checkMotion(self, a: Any, b: Any, *_: Any) -> bool:  # noqa: N802 - OMPL's name
            return self._planner._motion_is_free(a, b)

    return GridMotionValidator
