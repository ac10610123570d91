"""Planning grids: a voxel occupancy map turned into per-cell traversal costs.

A :class:`CostGrid` is what the grid planners search. Each cell carries a cost multiplier: 1 for
free space far from obstacles, more near obstacles (the risk band of D*+, 000 Sec VII-C) and in
unknown space when that is allowed, and infinity where the robot cannot be: occupied cells and
every cell whose centre lies closer than the robot radius to an occupied cell centre (Euclidean
inflation). Moving between neighbouring cells ``a`` and ``b`` costs
``|a - b| * (cost[a] + cost[b]) / 2``, the model of scikit-image's ``MCP_Geometric``.

Costs are computed either eagerly for the whole grid with a Euclidean distance transform (the
volumetric baseline builds its map once, outside the timed query) or lazily, cell by cell, when
the search first touches a cell (the mission's local planner works on a map that changes between
queries, so it pays only for the cells a query visits). Both use the same formula and give the
same numbers.

Ground robots plan on a planar grid: a column is occupied when any cell of the robot's height
band is occupied, unknown when none is occupied but some is unknown, and free otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import distance_transform_edt

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.threads import run_dealt, sensor_threads
from seminspect.geometry.transforms import as_point
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap

#: Distances within this of a threshold count as on it; the eager (EDT) and lazy (offset table)
#: paths compute the same distance with different rounding.
_DIST_EPS = 1e-9

# Indices into the packed model parameters handed to the compiled kernels.
_P_RADIUS, _P_RISK_RADIUS, _P_RISK_WEIGHT, _P_UNKNOWN = range(4)


@dataclass(frozen=True)
class CostModel:
    """How occupancy becomes cost.

    Attributes:
        robot_radius: cells whose centre is closer than this to an occupied cell centre are
            blocked [m].
        risk_radius: width of the band beyond ``robot_radius`` where a risk cost applies [m]. The
            default reads 000 Sec VII-C's "risk parameter of 0.2" for D*+ as this width: D*+'s
            risk setting is the size of its soft margin around occupied voxels.
        risk_weight: extra cost multiplier at the inner edge of the risk band, falling linearly to
            0 at its outer edge (our choice; D*+ uses a steep inverse-square falloff).
        unknown_cost: ``None`` blocks unknown cells; a number lets the robot cross them with
            that extra multiplier (``1 + unknown_cost`` per metre instead of 1).
    """

    robot_radius: float
    risk_radius: float = 0.2
    risk_weight: float = 1.0
    unknown_cost: float | None = None

    def __post_init__(self) -> None:
        for name in ("robot_radius", "risk_radius", "risk_weight"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise InvalidInputError(f"{name} must be a finite number >= 0, got {value!r}")
        unknown = self.unknown_cost
        if unknown is not None and not (
            isinstance(unknown, int | float) and math.isfinite(unknown) and unknown >= 0
        ):
            raise InvalidInputError(f"unknown_cost must be None or a number >= 0, got {unknown!r}")

    @property
    def has_risk(self) -> bool:
        return self.risk_radius > 0 and self.risk_weight > 0

    @property
    def reach(self) -> float:
        """Distance from an occupied cell beyond which it no longer changes any cost [m]."""
        return self.robot_radius + (self.risk_radius if self.has_risk else 0.0)

    def packed(self) -> NDArray[np.float64]:
        """The parameters as the compiled kernels take them (NaN unknown cost = blocked)."""
        unknown = math.nan if self.unknown_cost is None else float(self.unknown_cost)
        risk_weight = self.risk_weight if self.has_risk else 0.0
        return np.array([self.robot_radius, self.risk_radius, risk_weight, unknown])


def planar_states(voxel_map: VoxelMap, band: tuple[float, float]) -> NDArray[np.uint8]:
    """Project the height band ``[z_low, z_high]`` of a map to one layer, shape ``(nx, ny, 1)``.

    A voxel belongs to the band when its vertical extent overlaps it, so an obstacle that pokes
    into the band from below or above still blocks the column.
    """
    z_low, z_high = (float(v) for v in band)
    if not (math.isfinite(z_low) and math.isfinite(z_high) and z_low < z_high):
        raise InvalidInputError(f"height band must be finite with low < high, got {band!r}")
    res, z0 = voxel_map.resolution, float(voxel_map.origin[2])
    k_low = max(0, math.floor((z_low - z0) / res + 1e-9))
    k_high = min(voxel_map.shape[2], math.ceil((z_high - z0) / res - 1e-9))
    if k_low >= k_high:
        top = z0 + res * voxel_map.shape[2]
        raise InvalidInputError(
            f"height band [{z_low}, {z_high}] m misses the map, which spans z {z0:g}..{top:g} m"
        )
    states = voxel_map.states
    layer = np.empty((*voxel_map.shape[:2], 1), dtype=np.uint8)

    def project(rows: slice) -> None:
        _project_band(states, k_low, k_high, layer, rows.start, rows.stop)

    # Columns project independently: rows of the map are dealt out to the sensors' threads.
    run_dealt(project, states.shape[0], sensor_threads(), MIN_ROWS_PER_THREAD)
    return layer


#: Below this many map rows (of a few hundred columns each) per thread, one thread projects.
MIN_ROWS_PER_THREAD = 64


@numba.njit(cache=True, nogil=True)
def _project_band(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    states: np.ndarray, k_low: int, k_high: int, layer: np.ndarray, first: int, stop: int
) -> None:
    """Per column of rows ``first`` to ``stop - 1``: OCCUPIED if any band cell is, else UNKNOWN
    if any is, else FREE.

    One pass that stops at a column's first occupied cell, instead of two whole-band
    comparisons and their temporaries (the map is projected at every local plan).
    """
    for i in range(first, stop):
        for j in range(states.shape[1]):
            value = FREE
            for k in range(k_low, k_high):
                if states[i, j, k] == OCCUPIED:
                    value = OCCUPIED
                    break
                if states[i, j, k] == UNKNOWN:
                    value = UNKNOWN
            layer[i, j, 0] = value


def obstacle_offsets(
    reach: float, resolution: float, planar: bool
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Integer cell offsets closer than ``reach`` (excluding 0), sorted by their length [m]."""
    span = math.ceil(reach / resolution)
    axis = np.arange(-span, span + 1)
    dk = np.zeros(1, dtype=np.int64) if planar else axis
    grid = np.stack(np.meshgrid(axis, axis, dk, indexing="ij"), axis=-1).reshape(-1, 3)
    dist = resolution * np.sqrt((grid.astype(np.float64) ** 2).sum(axis=1))
    keep = (dist > 0) & (dist < reach + _DIST_EPS)
    order = np.argsort(dist[keep], kind="stable")
    return grid[keep][order].astype(np.int64), dist[keep][order]


@numba.njit(cache=True, inline="always")
def _cost_from_distance(state: int, dist: float, params: NDArray[np.float64]) -> float:
    """The cost multiplier of one cell given its state and clearance (shared by both paths)."""
    radius = params[_P_RADIUS]
    if state == OCCUPIED or dist < radius - _DIST_EPS:
        return math.inf
    cost = 1.0
    if state == UNKNOWN:
        if math.isnan(params[_P_UNKNOWN]):
            return math.inf
        cost += params[_P_UNKNOWN]
    risk_radius, weight = params[_P_RISK_RADIUS], params[_P_RISK_WEIGHT]
    if weight > 0.0 and dist < radius + risk_radius - _DIST_EPS:
        cost += weight * (1.0 - max(dist - radius, 0.0) / risk_radius)
    return cost


#: What the compiled kernels take for a grid: ``(states, cost, shape, params, offsets, dists)``
#: with ``states`` and ``cost`` flattened (C order) views of the grid arrays.
GridArgs = tuple


@numba.njit(cache=True)
def cell_cost(grid: GridArgs, flat: int) -> float:
    """Cost of a cell by flat index, evaluated on first use when its cached cost is still 0."""
    states, cost, shape, params, offsets, offset_dist = grid
    cached = cost[flat]
    if cached != 0.0:
        return cached
    nx, ny, nz = shape[0], shape[1], shape[2]
    i, rest = divmod(flat, ny * nz)
    j, k = divmod(rest, nz)
    dist = math.inf
    state = states[flat]
    if state != OCCUPIED:
        for n in range(offsets.shape[0]):  # nearest first: the first hit is the clearance
            a, b, c = i + offsets[n, 0], j + offsets[n, 1], k + offsets[n, 2]
            inside = 0 <= a < nx and 0 <= b < ny and 0 <= c < nz
            if inside and states[(a * ny + b) * nz + c] == OCCUPIED:
                dist = offset_dist[n]
                break
    value = np.float32(_cost_from_distance(state, dist, params))
    cost[flat] = value
    return value


@numba.njit(cache=True)
def _segment_is_free(grid: GridArgs, start: NDArray[np.float64], end: NDArray[np.float64]) -> bool:
    """Whether every cell the segment passes through (in cell units) is traversable.

    A voxel walk (Amanatides & Woo). Where the segment crosses exactly through an edge or corner
    it steps diagonally, like a diagonal grid move: touching a blocked cell only along an edge or
    at a corner counts as free, so raw grid routes pass the check too. Scalars throughout: small
    arrays per step would cost more than the walk.
    """
    shape = grid[2]
    cell = np.empty(3, dtype=np.int64)
    last = np.empty(3, dtype=np.int64)
    step = np.zeros(3, dtype=np.int64)
    t_max = np.full(3, np.inf)
    t_delta = np.full(3, np.inf)
    for a in range(3):
        cell[a] = int(min(max(math.floor(start[a]), 0.0), shape[a] - 1))
        last[a] = int(min(max(math.floor(end[a]), 0.0), shape[a] - 1))
        delta = end[a] - start[a]
        if delta != 0.0:
            step[a] = 1 if delta > 0.0 else -1
            boundary = cell[a] + (step[a] > 0)
            t_max[a] = (boundary - start[a]) / delta
            t_delta[a] = step[a] / delta
    cost = grid[1]
    i, j, k = cell[0], cell[1], cell[2]
    while True:
        flat = (i * shape[1] + j) * shape[2] + k
        value = cost[flat]
        if value == 0.0:  # not evaluated yet (lazy grid); a call only then, calls cost most
            value = cell_cost(grid, flat)
        if not math.isfinite(value):
            return False
        t_next = min(t_max[0], t_max[1], t_max[2])
        if (i == last[0] and j == last[1] and k == last[2]) or t_next > 1.0 + 1e-9:
            return True
        if t_max[0] <= t_next + 1e-9:
            i += step[0]
            t_max[0] += t_delta[0]
        if t_max[1] <= t_next + 1e-9:
            j += step[1]
            t_max[1] += t_delta[1]
        if t_max[2] <= t_next + 1e-9:
            k += step[2]
            t_max[2] += t_delta[2]
        if i < 0 or j < 0 or k < 0 or i >= shape[0] or j >= shape[1] or k >= shape[2]:
            return True


@numba.njit(cache=True)
def _segment_in_grid_is_free(
    grid: GridArgs, start: NDArray[np.float64], end: NDArray[np.float64]
) -> bool:
    """:func:`_segment_is_free` for ends that may lie outside the grid (then: not free)."""
    shape = grid[2]
    for a in range(3):
        for value in (start[a], end[a]):
            if not (0.0 <= value < shape[a]):
                return False
    return _segment_is_free(grid, start, end)


@numba.njit(cache=True)
def _shortcut(grid: GridArgs, cells: NDArray[np.float64]) -> NDArray[np.int64]:
    """From each kept waypoint, jump to the farthest later one joined by a free segment."""
    n = cells.shape[0]
    kept = np.empty(n, dtype=np.int64)
    kept[0], count, i = 0, 1, 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not _segment_in_grid_is_free(grid, cells[i], cells[j]):
            j -= 1
        kept[count] = j
        count += 1
        i = j
    return kept[:count]


@numba.njit(cache=True)
def _costs_of(grid: GridArgs, flat: NDArray[np.int64]) -> NDArray[np.float32]:
    out = np.empty(flat.shape[0], dtype=np.float32)
    for n in range(flat.shape[0]):
        out[n] = cell_cost(grid, flat[n])
    return out


def _eager_costs(
    states: NDArray[np.uint8], model: CostModel, resolution: float
) -> NDArray[np.float32]:
    """Costs of every cell from a Euclidean distance transform of the occupied cells."""
    occupied = states == OCCUPIED
    if occupied.any():
        dist = distance_transform_edt(~occupied, sampling=resolution)
    else:
        dist = np.full(states.shape, np.inf)
    params = model.packed()
    cost = np.ones(states.shape, dtype=np.float64)
    if model.unknown_cost is None:
        cost[states == UNKNOWN] = np.inf
    else:
        cost[states == UNKNOWN] += model.unknown_cost
    if model.has_risk:
        band = dist < model.reach - _DIST_EPS
        depth = np.maximum(dist[band] - model.robot_radius, 0.0) / model.risk_radius
        cost[band] += params[_P_RISK_WEIGHT] * (1.0 - depth)
    cost[occupied | (dist < model.robot_radius - _DIST_EPS)] = np.inf
    return cost.astype(np.float32)


@dataclass
class CostGrid:
    """A map ready to be searched: per-cell states and costs on a 3D or planar lattice.

    Attributes:
        origin: world coordinates of the minimum corner (for a planar grid only x and y matter).
        resolution: cell edge [m].
        states: ``uint8`` ``(nx, ny, nz)``; ``nz == 1`` for a planar (ground) grid.
        model: the cost model.
        planar: plan in x-y only (8-connected) instead of 3D (26-connected).
        cost: ``float32`` per-cell multipliers; 0 marks a cell not evaluated yet (lazy grids).
        lazy: whether costs are filled on demand.
    """

    origin: NDArray[np.float64]
    resolution: float
    states: NDArray[np.uint8]
    model: CostModel
    planar: bool
    cost: NDArray[np.float32]
    lazy: bool

    def __post_init__(self) -> None:
        offsets, offset_dist = obstacle_offsets(self.model.reach, self.resolution, self.planar)
        self.kernel_args: GridArgs = (
            self.states.reshape(-1),
            self.cost.reshape(-1),
            np.asarray(self.shape, dtype=np.int64),
            self.model.packed(),
            offsets,
            offset_dist,
        )

    @classmethod
    def build(
        cls,
        voxel_map: VoxelMap,
        model: CostModel,
        band: tuple[float, float] | None = None,
        lazy: bool = False,
    ) -> CostGrid:
        """Costs for ``voxel_map``; ``band`` (ground robots) plans on that height band."""
        states = voxel_map.states if band is None else planar_states(voxel_map, band)
        states = np.ascontiguousarray(states)
        if lazy:
            cost = np.zeros(states.shape, dtype=np.float32)
        else:
            cost = _eager_costs(states, model, voxel_map.resolution)
        return cls(
            voxel_map.origin.copy(),
            voxel_map.resolution,
            states,
            model,
            band is not None,
            cost,
            lazy,
        )

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.states.shape  # type: ignore[return-value]

    def cell_of(self, point: ArrayLike, what: str) -> NDArray[np.int64]:
        """The cell holding ``point``; a :class:`PlanningError` naming ``what`` if outside."""
        p = as_point(point, what)
        idx = np.floor((p - self.origin) / self.resolution).astype(np.int64)
        if self.planar:
            idx[2] = 0
        if np.any(idx < 0) or np.any(idx >= np.asarray(self.shape)):
            upper = self.origin + self.resolution * np.asarray(self.shape)
            axes = 2 if self.planar else 3
            raise PlanningError(
                f"{what} {format_point(p)} is outside the map "
                f"({format_point(self.origin[:axes])} to {format_point(upper[:axes])})"
            )
        return idx

    def flat_index(self, cells: ArrayLike) -> NDArray[np.int64]:
        idx = np.asarray(cells, dtype=np.int64)
        _, ny, nz = self.shape
        return (idx[..., 0] * ny + idx[..., 1]) * nz + idx[..., 2]

    def centres(self, cells: ArrayLike, z: float = 0.0) -> NDArray[np.float64]:
        """World centres of cells; planar grids put them at height ``z``."""
        pts = self.origin + (np.asarray(cells, dtype=np.float64) + 0.5) * self.resolution
        if self.planar:
            pts[..., 2] = z
        return pts

    def costs_of(self, cells: ArrayLike) -> NDArray[np.float32]:
        """Cost multipliers of cells ``(..., 3)``, evaluating lazy ones."""
        flat = np.atleast_1d(self.flat_index(cells)).ravel()
        return _costs_of(self.kernel_args, flat).reshape(np.shape(cells)[:-1])

    def segment_is_free(self, a: ArrayLike, b: ArrayLike) -> bool:
        """Whether the straight segment ``a -> b`` (world points) crosses only traversable cells.

        Both ends must lie in the grid (planar grids ignore z).
        """
        ends = self._cell_units(np.array([a, b], dtype=np.float64))
        return bool(_segment_in_grid_is_free(self.kernel_args, ends[0], ends[1]))

    def shortcut(self, waypoints: NDArray[np.float64]) -> NDArray[np.int64]:
        """Indices of the waypoints ``(N, 3)`` that greedy shortcutting with
        :meth:`segment_is_free` keeps (see :func:`~seminspect.planning.smoothing.shortcut`),
        the whole loop in one compiled call."""
        return _shortcut(
            self.kernel_args, self._cell_units(np.asarray(waypoints, dtype=np.float64))
        )

    def _cell_units(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """World points in (fractional) cell units; planar grids put them mid-layer."""
        units = (points - self.origin) / self.resolution
        if self.planar:
            units[:, 2] = 0.5
        return units


def format_point(point: ArrayLike) -> str:
    """``(x, y, z)`` with centimetre precision, for error messages."""
    return "(" + ", ".join(f"{v:.2f}" for v in np.asarray(point, dtype=float)) + ")"
