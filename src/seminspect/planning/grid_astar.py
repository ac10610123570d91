"""The compiled grid search shared by the volumetric baseline and the local planner.

A* over a :class:`~seminspect.planning.gridmap.CostGrid`: 26-connected in 3D, 8-connected on a
planar grid, with the octile distance as heuristic (admissible and consistent because every cost
multiplier is at least 1), ties broken towards the larger cost-so-far. Without the heuristic it is
Dijkstra's algorithm. A goal may be a region: any traversable cell whose centre lies within
``goal_radius`` of the goal point, because inspection targets sit inside occupied space.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.geometry.transforms import as_point
from seminspect.planning.gridmap import CostGrid, GridArgs, cell_cost, format_point
from seminspect.planning.smoothing import path_length

_SQRT2 = math.sqrt(2.0)
_SQRT3 = math.sqrt(3.0)
_HEAP_START = 1 << 14


@dataclass(frozen=True)
class GridPath:
    """A planned route.

    Attributes:
        waypoints: ``(N, 3)`` world points from the start to the end of the route.
        length: length of the polyline through ``waypoints`` [m].
        cost: value of the search objective (length weighted by cell costs).
        expansions: cells the search settled (for engines that do not report it, the cells
            they reached).
        planning_time: wall time of the query [s], map preparation excluded.
        engine: which search produced it.
        cells: ``(M, 3)`` grid cells of the raw route, start cell first.
    """

    waypoints: NDArray[np.float64]
    length: float
    cost: float
    expansions: int
    planning_time: float
    engine: str
    cells: NDArray[np.int64]


def neighbour_steps(planar: bool) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The 26 (3D) or 8 (planar) neighbour offsets and their lengths in cells."""
    dks = (0,) if planar else (-1, 0, 1)
    steps = [s for s in itertools.product((-1, 0, 1), (-1, 0, 1), dks) if any(s)]
    arr = np.array(steps, dtype=np.int64)
    return arr, np.sqrt((arr**2).sum(axis=1).astype(np.float64))


@numba.njit(cache=True, inline="always")
def _octile(di: int, dj: int, dk: int) -> float:
    a, b, c = abs(di), abs(dj), abs(dk)
    if a < b:
        a, b = b, a
    if b < c:
        b, c = c, b
    if a < b:
        a, b = b, a
    return (a - b) + _SQRT2 * (b - c) + _SQRT3 * c


@numba.njit(cache=True, inline="always")
def _before(heap: NDArray[np.float64], n: int, f: float, g: float) -> bool:
    """Whether heap entry ``n`` comes before ``(f, g)``: lower f, then higher g (nearer goal)."""
    return heap[n, 0] < f or (heap[n, 0] == f and heap[n, 1] > g)


@numba.njit(cache=True)
def _heap_push(heap: NDArray[np.float64], size: int, f: float, g: float, v: int) -> int:
    """Binary-heap push of ``(f, g, v)`` rows; returns the new size (capacity is the caller's)."""
    pos = size
    while pos > 0:
        up = (pos - 1) >> 1
        if not (f < heap[up, 0] or (f == heap[up, 0] and g > heap[up, 1])):
            break
        heap[pos, 0], heap[pos, 1], heap[pos, 2] = heap[up, 0], heap[up, 1], heap[up, 2]
        pos = up
    heap[pos, 0], heap[pos, 1], heap[pos, 2] = f, g, v
    return size + 1


@numba.njit(cache=True)
def _heap_pop(heap: NDArray[np.float64], size: int) -> tuple[int, int]:
    """Remove the first row; returns its cell and the new size."""
    top = int(heap[0, 2])
    size -= 1
    f, g, v = heap[size, 0], heap[size, 1], heap[size, 2]
    pos = 0
    while True:
        child = 2 * pos + 1
        if child >= size:
            break
        if child + 1 < size and _before(heap, child + 1, heap[child, 0], heap[child, 1]):
            child += 1
        if not _before(heap, child, f, g):
            break
        heap[pos, 0], heap[pos, 1], heap[pos, 2] = heap[child, 0], heap[child, 1], heap[child, 2]
        pos = child
    if size > 0:
        heap[pos, 0], heap[pos, 1], heap[pos, 2] = f, g, v
    return top, size


#: A packed goal for :func:`astar_kernel`: the goal cell ``(i, j, k)``; the goal point in cell
#: units; the squared goal radius in cells (negative: the goal cell only); the heuristic offset
#: [m]; the heuristic weight; the cell size [m].
GoalArgs = NDArray[np.float64]
_G_RADIUS2, _G_OFFSET, _G_WEIGHT, _G_RES = 6, 7, 8, 9


@numba.njit(cache=True, inline="always")
def _in_goal_region(goal: GoalArgs, i: int, j: int, k: int) -> bool:
    dx, dy, dz = i + 0.5 - goal[3], j + 0.5 - goal[4], k + 0.5 - goal[5]
    return goal[_G_RADIUS2] >= 0.0 and dx * dx + dy * dy + dz * dz <= goal[_G_RADIUS2]


@numba.njit(cache=True)
def _trace_route(
    parent: NDArray[np.int8], deltas: NDArray[np.int64], start: int, end: int
) -> NDArray[np.int64]:
    """Flat cells from ``start`` to ``end`` by following parent steps back."""
    count = 1
    v = end
    while v != start:
        v -= deltas[parent[v]]
        count += 1
    route = np.empty(count, dtype=np.int64)
    for n in range(count - 1, -1, -1):
        route[n] = end
        if n > 0:
            end -= deltas[parent[end]]
    return route


@numba.njit(cache=True)
def astar_kernel(
    grid: GridArgs,
    moves: tuple[NDArray[np.int64], NDArray[np.float64]],
    start: int,
    goal: GoalArgs,
) -> tuple[int, int, int, float, NDArray[np.int64]]:
    """Search from flat cell ``start`` to the goal region.

    ``moves`` holds the neighbour offsets and their lengths [m]. A cell is a goal when it is the
    goal cell or its centre lies within the goal radius of the goal point. The heuristic is the
    octile distance to the goal cell less the offset (so it stays admissible for every cell of the
    goal region), times the weight: 1 is A* (optimal), 0 Dijkstra, above 1 weighted A* (a route
    at most that many times the optimal cost, found with far fewer expansions).

    Returns ``(end cell or -1, cells settled, heap pushes, cost, route of flat cells)``.
    """
    cost, shape = grid[1], grid[2]
    steps, lengths = moves
    nx, ny, nz = shape[0], shape[1], shape[2]
    status = np.zeros(nx * ny * nz, dtype=np.uint8)  # 0 new, 1 open, 2 closed
    g = np.empty(nx * ny * nz, dtype=np.float64)
    parent = np.empty(nx * ny * nz, dtype=np.int8)
    deltas = (steps[:, 0] * ny + steps[:, 1]) * nz + steps[:, 2]
    gi, gj, gk = int(goal[0]), int(goal[1]), int(goal[2])
    goal_flat = (gi * ny + gj) * nz + gk
    h_weight, h_offset, res = goal[_G_WEIGHT], goal[_G_OFFSET], goal[_G_RES]
    heap = np.empty((_HEAP_START, 3), dtype=np.float64)  # rows (f, g, cell); cells < 2**53
    g[start] = 0.0
    status[start] = 1
    size = _heap_push(heap, 0, 0.0, 0.0, start)
    expansions = 0
    pushes = 1
    while size > 0:
        v, size = _heap_pop(heap, size)
        if status[v] == 2:
            continue  # a stale duplicate; the cell was settled with a smaller cost
        status[v] = 2
        expansions += 1
        i, rest = divmod(v, ny * nz)
        j, k = divmod(rest, nz)
        if v == goal_flat or _in_goal_region(goal, i, j, k):
            return v, expansions, pushes, g[v], _trace_route(parent, deltas, start, v)
        cv = np.float64(cost[v])  # evaluated when v was reached; sums in double precision
        for d in range(steps.shape[0]):
            a, b, c = i + steps[d, 0], j + steps[d, 1], k + steps[d, 2]
            if not (0 <= a < nx and 0 <= b < ny and 0 <= c < nz):
                continue
            u = v + deltas[d]
            if status[u] == 2:
                continue
            cu = np.float64(cost[u])
            if cu == 0.0:  # a lazy grid meets this cell for the first time
                cu = np.float64(cell_cost(grid, u))
            ng = g[v] + lengths[d] * 0.5 * (cv + cu)
            if cu == math.inf or (status[u] == 1 and ng >= g[u]):
                continue
            g[u] = ng
            parent[u] = d
            status[u] = 1
            h = h_weight * max(_octile(a - gi, b - gj, c - gk) * res - h_offset, 0.0)
            if size == heap.shape[0]:
                heap = np.concatenate((heap, np.empty_like(heap)))
            size = _heap_push(heap, size, ng + h, ng, u)
            pushes += 1
    return -1, expansions, pushes, math.inf, np.empty(0, dtype=np.int64)


@dataclass(frozen=True)
class Query:
    """A validated query on a grid: the start and goal cells and the goal region."""

    start: NDArray[np.float64]
    goal: NDArray[np.float64]
    start_cell: NDArray[np.int64]
    goal_cell: NDArray[np.int64]
    goal_radius: float
    #: cells of the goal region that are traversable (the goal cell alone when radius is 0)
    goal_cells: NDArray[np.int64]
    #: largest octile distance [m] from the goal cell to any cell of the goal region
    h_offset: float

    def goal_point_cells(self, grid: CostGrid) -> NDArray[np.float64]:
        point = (self.goal - grid.origin) / grid.resolution
        if grid.planar:
            point[2] = 0.5
        return point


def _cells_within(grid: CostGrid, point: NDArray[np.float64], radius: float) -> NDArray[np.int64]:
    """Cells whose centre lies within ``radius`` of ``point`` (x-y only on planar grids)."""
    res = grid.resolution
    lo = np.floor((point - radius - grid.origin) / res).astype(np.int64)
    hi = np.floor((point + radius - grid.origin) / res).astype(np.int64) + 1
    lo, hi = np.maximum(lo, 0), np.minimum(hi, np.asarray(grid.shape))
    if grid.planar:
        lo[2], hi[2] = 0, 1
    axes = [np.arange(a, b) for a, b in zip(lo, hi, strict=True)]
    cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    delta = grid.origin + (cells + 0.5) * res - point
    if grid.planar:
        delta[:, 2] = 0.0
    return cells[np.einsum("ij,ij->i", delta, delta) <= radius * radius + 1e-12]


def _blocked_reason(grid: CostGrid) -> str:
    reason = f"inside an obstacle or within the robot radius {grid.model.robot_radius:g} m of one"
    if grid.model.unknown_cost is None:
        reason += ", or in unknown space"
    return reason


def make_query(
    grid: CostGrid,
    start: ArrayLike,
    goal: ArrayLike,
    goal_radius: float = 0.0,
    start_tolerance: float = 0.0,
) -> Query:
    """Validate a query; :class:`PlanningError` names the end that is outside or blocked.

    ``start_tolerance`` lets a start that is blocked (a robot closer to a wall than its radius)
    begin from the nearest traversable cell within that distance instead.
    """
    for name, value in (("goal_radius", goal_radius), ("start_tolerance", start_tolerance)):
        if not (math.isfinite(value) and value >= 0):
            raise InvalidInputError(f"{name} must be a finite number >= 0, got {value!r}")
    start_pt, goal_pt = as_point(start, "start"), as_point(goal, "goal")
    start_cell = grid.cell_of(start_pt, "start")
    goal_cell = grid.cell_of(goal_pt, "goal")
    if not math.isfinite(grid.costs_of(start_cell)):
        start_cell = _escape(grid, start_pt, start_tolerance)
    candidates = _cells_within(grid, goal_pt, goal_radius) if goal_radius > 0 else goal_cell[None]
    candidates = np.unique(np.vstack([candidates, goal_cell[None]]), axis=0)
    goal_cells = candidates[np.isfinite(grid.costs_of(candidates))]
    if goal_cells.size == 0:
        if goal_radius > 0:
            raise PlanningError(
                f"no traversable cell within {goal_radius:g} m of the goal {format_point(goal_pt)}"
            )
        raise PlanningError(
            f"goal {format_point(goal_pt)} is {_blocked_reason(grid)}; "
            "give a goal radius to stop next to it"
        )
    big, mid, small = np.sort(np.abs(candidates - goal_cell), axis=1)[:, ::-1].T
    octile = (big - mid) + _SQRT2 * (mid - small) + _SQRT3 * small
    return Query(
        start_pt,
        goal_pt,
        start_cell,
        goal_cell,
        float(goal_radius),
        goal_cells,
        float(octile.max()) * grid.resolution,
    )


def _escape(grid: CostGrid, start: NDArray[np.float64], tolerance: float) -> NDArray[np.int64]:
    cells = _cells_within(grid, start, tolerance) if tolerance > 0 else np.empty((0, 3), int)
    free = cells[np.isfinite(grid.costs_of(cells))] if cells.size else cells
    if free.size == 0:
        raise PlanningError(f"start {format_point(start)} is {_blocked_reason(grid)}")
    delta = grid.centres(free, start[2]) - start
    return free[int(np.argmin(np.einsum("ij,ij->i", delta, delta)))]


def _route_waypoints(grid: CostGrid, query: Query, cells: NDArray[np.int64]) -> NDArray[np.float64]:
    """World waypoints of a cell route: the exact start, the cell centres, the exact goal when
    the goal is a single cell. Planar grids keep the start's height throughout."""
    z = float(query.start[2])
    centres = grid.centres(cells, z)
    points = [query.start[None], centres]
    if query.goal_radius == 0:
        goal = query.goal.copy()
        if grid.planar:
            goal[2] = z
        points.append(goal[None])
    waypoints = np.vstack(points)
    keep = np.ones(len(waypoints), dtype=bool)
    keep[1:] = np.any(np.abs(np.diff(waypoints, axis=0)) > 1e-12, axis=1)
    return waypoints[keep]


def make_path(
    grid: CostGrid,
    query: Query,
    cells: NDArray[np.int64],
    *,
    cost: float,
    expansions: int,
    engine: str,
    started: float,
) -> GridPath:
    """Package a cell route found by any engine; ``started`` is the query's ``perf_counter``."""
    waypoints = _route_waypoints(grid, query, cells)
    return GridPath(
        waypoints=waypoints,
        length=path_length(waypoints),
        cost=float(cost),
        expansions=int(expansions),
        planning_time=time.perf_counter() - started,
        engine=engine,
        cells=cells,
    )


def no_path_error(query: Query, searched: int) -> PlanningError:
    return PlanningError(
        f"no path from {format_point(query.start)} to {format_point(query.goal)}: "
        f"the goal is cut off ({searched} cells searched)"
    )


def search(
    grid: CostGrid, query: Query, h_weight: float = 1.0, started: float | None = None
) -> GridPath:
    """Run the compiled search for a validated query.

    ``h_weight`` 1 is A*, 0 Dijkstra, above 1 weighted A* (see :func:`astar_kernel`).
    ``started`` (a ``perf_counter`` value) lets the caller include its own preparation in the
    reported planning time.
    """
    started = time.perf_counter() if started is None else started
    steps, step_len = neighbour_steps(grid.planar)
    radius2 = (query.goal_radius / grid.resolution) ** 2 if query.goal_radius > 0 else -1.0
    goal = np.concatenate(
        [
            query.goal_cell.astype(np.float64),
            query.goal_point_cells(grid),
            [radius2, query.h_offset, h_weight, grid.resolution],
        ]
    )
    start = int(grid.flat_index(query.start_cell))
    moves = (steps, step_len * grid.resolution)
    end, expansions, _, cost, flat = astar_kernel(grid.kernel_args, moves, start, goal)
    if end < 0:
        raise no_path_error(query, expansions)
    cells = np.stack(np.unravel_index(flat, grid.shape), axis=-1).astype(np.int64)
    engine = "dijkstra" if h_weight == 0 else "astar" if h_weight == 1 else f"astar-w{h_weight:g}"
    return make_path(
        grid, query, cells, cost=cost, expansions=expansions, engine=engine, started=started
    )
