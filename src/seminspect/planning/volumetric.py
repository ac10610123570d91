"""The volumetric baseline: shortest paths on a voxel occupancy map (000 Sec VII-C, Table 5).

The paper compares its hierarchical planner with D*+ running on an OctoMap at 0.5 m and 0.7 m
(and 0.4 m in the mission study, Sec VII-D), with a risk parameter of 0.2. This module is our
peer: optimal 26-connected (aerial) or 8-connected (ground) paths on a
:class:`~seminspect.planning.gridmap.CostGrid` with Euclidean inflation by the robot radius, the
D*+-style risk band and configurable unknown space, built once when the planner is made so a
query only searches, as in the paper. D*+ is D* Lite, which pays off when the map changes under
a moving robot; for one query on a fixed map it returns the same optimal path as A*, which is
what runs here.

Four engines answer the same query on the same costs and give the same optimal cost; they exist
so ``bench/grid_planning.py`` can compare them:

- ``astar``: the compiled A* of :mod:`~seminspect.planning.grid_astar` (the default, fastest);
- ``dijkstra``: the same kernel without its heuristic;
- ``mcp``: scikit-image's ``MCP_Geometric`` (Cython Dijkstra, stops at the first goal);
- ``csgraph``: scipy's ``csgraph.dijkstra`` on a sparse graph of the grid (full single-source).
"""

from __future__ import annotations

import dataclasses
import time
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import sparse
from scipy.sparse import csgraph
from skimage.graph import MCP_Geometric

from seminspect.core.names import unknown_name
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.grid_astar import (
    GridPath,
    Query,
    make_path,
    make_query,
    neighbour_steps,
    no_path_error,
    search,
)
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.smoothing import path_length, refine_path

Engine = Literal["astar", "dijkstra", "mcp", "csgraph"]
ENGINES: tuple[str, ...] = ("astar", "dijkstra", "mcp", "csgraph")


class VolumetricPlanner:
    """Optimal grid paths on a fixed voxel map.

    Args:
        voxel_map: the occupancy map (read once; later changes to it are not seen).
        model: inflation, risk and unknown-space settings.
        band: ``(z_low, z_high)`` plans for a ground robot on that height band (8-connected);
            ``None`` plans in 3D (26-connected).
        engine: one of :data:`ENGINES`.

    Attributes:
        grid: the prepared :class:`CostGrid`.
        build_time: seconds spent preparing the map (inflation, engine set-up).
    """

    def __init__(
        self,
        voxel_map: VoxelMap,
        model: CostModel,
        band: tuple[float, float] | None = None,
        engine: Engine = "astar",
    ) -> None:
        if engine not in ENGINES:
            raise unknown_name("planning engine", engine, ENGINES)
        t0 = time.perf_counter()
        self.engine = engine
        self.grid = CostGrid.build(voxel_map, model, band)
        self._mcp: MCP_Geometric | None = None
        self._graph: sparse.csr_matrix | None = None
        if engine == "mcp":
            costs = self.grid.cost[:, :, 0] if self.grid.planar else self.grid.cost
            sampling = (self.grid.resolution,) * costs.ndim
            self._mcp = MCP_Geometric(costs.astype(np.float64), sampling=sampling)
        elif engine == "csgraph":
            self._graph = grid_graph(self.grid)
        self.build_time = time.perf_counter() - t0

    def plan(
        self,
        start: ArrayLike,
        goal: ArrayLike,
        goal_radius: float = 0.0,
        start_tolerance: float = 0.0,
    ) -> GridPath:
        """Shortest path from ``start`` to ``goal`` (or to any free cell within ``goal_radius``).

        A start that is blocked (a robot standing closer to an obstacle than the inflation, as
        happens on a coarse map) begins from the nearest traversable cell within
        ``start_tolerance``.

        Raises:
            PlanningError: start or goal outside the map or blocked, or no route exists.
        """
        t0 = time.perf_counter()
        query = make_query(self.grid, start, goal, goal_radius, start_tolerance)
        if self.engine == "mcp":
            return self._plan_mcp(query, t0)
        if self.engine == "csgraph":
            return self._plan_csgraph(query, t0)
        return search(self.grid, query, 1.0 if self.engine == "astar" else 0.0, started=t0)

    def _plan_mcp(self, query: Query, t0: float) -> GridPath:
        assert self._mcp is not None
        dims = 2 if self.grid.planar else 3
        ends = [tuple(c[:dims]) for c in query.goal_cells]
        cumulative, _ = self._mcp.find_costs([tuple(query.start_cell[:dims])], ends, False)
        reached = cumulative[tuple(query.goal_cells[:, :dims].T)]
        if not np.isfinite(reached).any():
            raise no_path_error(query, int(np.isfinite(cumulative).sum()))
        end = query.goal_cells[int(np.argmin(reached))]
        route = np.asarray(self._mcp.traceback(tuple(end[:dims])), dtype=np.int64)
        cells = np.column_stack([route, np.zeros(len(route), np.int64)]) if dims == 2 else route
        searched = int(np.isfinite(cumulative).sum())
        cost = float(reached.min())
        return make_path(
            self.grid, query, cells, cost=cost, expansions=searched, engine="mcp", started=t0
        )

    def _plan_csgraph(self, query: Query, t0: float) -> GridPath:
        start = int(self.grid.flat_index(query.start_cell))
        dist, pred = csgraph.dijkstra(
            self._graph, directed=False, indices=start, return_predecessors=True
        )
        goals = self.grid.flat_index(query.goal_cells)
        searched = int(np.isfinite(dist).sum())
        if not np.isfinite(dist[goals]).any():
            raise no_path_error(query, searched)
        node = int(goals[int(np.argmin(dist[goals]))])
        cost = float(dist[node])
        route = [node]
        while node != start:
            node = int(pred[node])
            route.append(node)
        cells = np.stack(np.unravel_index(route[::-1], self.grid.shape), axis=-1)
        return make_path(
            self.grid,
            query,
            cells.astype(np.int64),
            cost=cost,
            expansions=searched,
            engine="csgraph",
            started=t0,
        )


class RebuildingVolumetricPlanner:
    """The volumetric baseline inside a mission (000 Sec VII-D's "FLIE + 3DLSG + D*+").

    Every query takes the robot's current map, coarsens it to the baseline's ``resolution``
    (0.4 m in the paper) when it is finer, rebuilds the whole cost grid (inflation, risk band,
    unknown space at a cost) and runs the optimal A*, then drops the grid route's collinear points
    and takes straight shortcuts on the same grid, as the paper's D*+ smooths its route with a
    spline. ``planning_time`` counts the grid build, the search and the shortcuts; coarsening
    stands in for the baseline's own map, which it would maintain anyway, and is not counted.
    It answers the mission's navigator like :class:`~seminspect.planning.routes.LocalPlanner`.
    """

    def __init__(
        self,
        model: CostModel,
        band: tuple[float, float] | None,
        resolution: float = 0.4,
        start_tolerance: float | None = None,
    ) -> None:
        self.model = model
        self.band = band
        self.resolution = float(resolution)
        self.start_tolerance = model.robot_radius if start_tolerance is None else start_tolerance

    def plan(
        self, voxel_map: VoxelMap, start: ArrayLike, goal: ArrayLike, goal_radius: float = 0.0
    ) -> GridPath:
        coarse = (
            voxel_map
            if voxel_map.resolution >= self.resolution
            else voxel_map.coarsened(self.resolution)
        )
        t0 = time.perf_counter()
        planner = VolumetricPlanner(coarse, self.model, self.band)
        raw = planner.plan(start, goal, goal_radius, self.start_tolerance)
        refined = refine_path(raw.waypoints, planner.grid).waypoints
        return dataclasses.replace(
            raw,
            waypoints=refined,
            length=path_length(refined),
            planning_time=time.perf_counter() - t0,
            engine="volumetric-rebuilt",
        )


def grid_graph(grid: CostGrid) -> sparse.csr_matrix:
    """The grid as an undirected sparse graph with the same edge costs as the grid search."""
    cost = grid.cost.astype(np.float64)
    index = np.arange(cost.size, dtype=np.int64).reshape(cost.shape)
    steps, step_len = neighbour_steps(grid.planar)
    rows: list[NDArray[np.int64]] = []
    cols: list[NDArray[np.int64]] = []
    weights: list[NDArray[np.float64]] = []
    for step, length in zip(steps, step_len, strict=True):
        if tuple(step) <= (0, 0, 0):
            continue  # each undirected edge once
        src = tuple(slice(max(0, -s), n - max(0, s)) for s, n in zip(step, cost.shape, strict=True))
        dst = tuple(slice(max(0, s), n - max(0, -s)) for s, n in zip(step, cost.shape, strict=True))
        w = length * grid.resolution * 0.5 * (cost[src] + cost[dst])
        ok = np.isfinite(w)
        rows.append(index[src][ok])
        cols.append(index[dst][ok])
        weights.append(w[ok])
    n = cost.size
    return sparse.csr_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
