"""Layer 3: terrain-aware place nodes, one GVD per terrain type (001 Sec III-B.3).

All terrain types share one grid over the task points, so that their places line up. Each
terrain's points fill a boolean grid; :func:`seminspect.graphs.terrain.gvd.build_gvd` turns it
into nodes and links. Every terrain cell is then given to its geodesically closest place of the
same terrain (a flood fill over the terrain patch), which yields each place's area, height and
points. 001 builds one GVD per terrain and does not say how they meet; for navigation across
terrain types, places of different terrain whose cells touch are linked as ``traversable``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.sparse.csgraph import connected_components

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.terrain.gvd import GvdResult, build_gvd, cell_graph, flood_fill
from seminspect.graphs.terrain.params import TerrainGraphParams
from seminspect.graphs.terrain.prompting import TaskPoints

#: Refuse terrain grids larger than this many cells (a 5 km square at 0.5 m is 100 M cells).
MAX_GRID_CELLS = 50_000_000
_TOUCH = ((0, 0), (0, 1), (1, 0), (0, -1), (-1, 0))
#: Warn when the places fall into more unlinked groups than this share of them (SemanticKITTI's
#: three scans: 15 groups of 158 places, far-range rings; Autzen at 0.5 m cells: 266 of 569).
FRAGMENTED_SHARE = 0.25
_FRAGMENTED_MIN_GROUPS = 5


class TerrainWarning(UserWarning):
    """A terrain graph that builds, though probably not as its user means."""


@dataclass(frozen=True)
class GridFrame:
    """A 2D grid over x-y: cell ``(i, j)`` covers ``origin + cell * [i, i+1) x [j, j+1)``."""

    origin: tuple[float, float]
    cell: float
    shape: tuple[int, int]

    @classmethod
    def around(cls, points: NDArray[np.float64], cell: float) -> GridFrame:
        """The grid covering the x-y extent of ``points`` with one spare cell on each side."""
        low = points[:, :2].min(axis=0) - cell
        high = points[:, :2].max(axis=0) + cell
        shape = tuple(int(n) for n in np.ceil((high - low) / cell) + 1)
        if math.prod(shape) > MAX_GRID_CELLS:
            raise InvalidInputError(
                f"a {cell} m terrain grid over this cloud needs {math.prod(shape):,} cells; "
                "use a larger cell size"
            )
        return cls((float(low[0]), float(low[1])), float(cell), (shape[0], shape[1]))

    def cells_of(self, points: NDArray[np.float64]) -> NDArray[np.int64]:
        """``(N, 2)`` cell indices of points (their x and y)."""
        return np.floor((points[:, :2] - np.asarray(self.origin)) / self.cell).astype(np.int64)

    def centres(self, cells: NDArray[np.int64]) -> NDArray[np.float64]:
        """x-y centres of ``(N, 2)`` cells."""
        return np.asarray(self.origin) + (np.asarray(cells, dtype=np.float64) + 0.5) * self.cell


@dataclass(frozen=True)
class Place:
    """One terrain-aware place node."""

    terrain: str
    cell: tuple[int, int]
    position: NDArray[np.float64]
    clearance: float  # distance to the terrain's edge, metres
    area: float  # area of the terrain cells it owns, square metres


@dataclass
class PlaceLayer:
    """All places, their links and the per-terrain GVD stages."""

    frame: GridFrame
    places: list[Place] = field(default_factory=list)
    edges: list[tuple[int, int, float, str]] = field(default_factory=list)
    gvd: dict[str, GvdResult] = field(default_factory=dict)
    cell_owner: dict[str, NDArray[np.int64]] = field(default_factory=dict)
    point_place: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, np.int64))


def _terrain_grid(
    frame: GridFrame, points: NDArray[np.float64], min_points: int
) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
    """Occupancy, per-cell point count and per-cell height sum of one terrain's points."""
    cells = frame.cells_of(points)
    flat = np.ravel_multi_index((cells[:, 0], cells[:, 1]), frame.shape)
    size = frame.shape[0] * frame.shape[1]
    counts: NDArray[np.float64] = (
        np.bincount(flat, minlength=size).reshape(frame.shape).astype(np.float64)
    )
    heights = cast(
        "NDArray[np.float64]",
        np.bincount(flat, weights=points[:, 2], minlength=size).reshape(frame.shape),
    )
    return counts >= min_points, counts, heights


def _own_cells(result: GvdResult) -> NDArray[np.int64]:
    """Local node index owning each cleaned terrain cell (geodesic flood fill), -1 elsewhere."""
    owner = np.full(result.cleaned.shape, -1, dtype=np.int64)
    if result.nodes.shape[0] == 0:
        return owner
    graph = cell_graph(result.cleaned)
    sources = graph.index[result.nodes[:, 0], result.nodes[:, 1]]
    _, _, nearest = flood_fill(graph, sources)
    owner[graph.cells[:, 0], graph.cells[:, 1]] = nearest
    return owner


def _place_heights(
    owner: NDArray[np.int64], counts: NDArray[np.float64], heights: NDArray[np.float64], n: int
) -> NDArray[np.float64]:
    """Mean height of the terrain points in each place's cells (the terrain's mean if none)."""
    owned = owner >= 0
    point_total = np.bincount(owner[owned], weights=counts[owned], minlength=n)
    height_total = np.bincount(owner[owned], weights=heights[owned], minlength=n)
    fallback = heights.sum() / max(counts.sum(), 1.0)
    return np.where(point_total > 0, height_total / np.maximum(point_total, 1.0), fallback)


def _traversable(layer: PlaceLayer) -> list[tuple[int, int, float, str]]:
    """Links between places of different terrain whose cells overlap or touch."""
    pairs: set[tuple[int, int]] = set()
    grids = list(layer.cell_owner.values())
    for i, first in enumerate(grids):
        for second in grids[i + 1 :]:
            for dr, dc in _TOUCH:
                shifted = np.full_like(second, -1)
                rows = slice(max(dr, 0), second.shape[0] + min(dr, 0))
                cols = slice(max(dc, 0), second.shape[1] + min(dc, 0))
                back_rows = slice(max(-dr, 0), second.shape[0] + min(-dr, 0))
                back_cols = slice(max(-dc, 0), second.shape[1] + min(-dc, 0))
                shifted[rows, cols] = second[back_rows, back_cols]
                both = (first >= 0) & (shifted >= 0)
                found = np.unique(np.column_stack([first[both], shifted[both]]), axis=0)
                pairs.update((int(a), int(b)) for a, b in found)
    links = []
    for a, b in sorted(pairs):
        length = float(np.linalg.norm(layer.places[a].position - layer.places[b].position))
        links.append((min(a, b), max(a, b), length, "traversable"))
    return links


def build_places(layer: TaskPoints, params: TerrainGraphParams) -> PlaceLayer:
    """Place nodes for every terrain prompt of the task (001 Sec III-B.3)."""
    cell = params.cell_size
    terrain_rows = np.flatnonzero(layer.classes < len(layer.prompts.terrain))
    if terrain_rows.size == 0:
        return PlaceLayer(GridFrame((0.0, 0.0), cell, (0, 0)))
    frame = GridFrame.around(layer.points[terrain_rows], cell)
    result = PlaceLayer(frame, point_place=np.full(layer.points.shape[0], -1, dtype=np.int64))
    for terrain in layer.prompts.terrain:
        rows = layer.of(terrain)
        if rows.size == 0:
            continue
        occupancy, counts, heights = _terrain_grid(
            frame, layer.points[rows], params.min_points_per_cell
        )
        gvd = build_gvd(
            occupancy,
            smoothing_cells=params.smoothing_cells,
            min_patch_cells=math.ceil(params.min_patch_area / cell**2),
            min_branch_cells=math.ceil(params.prune_length / cell),
            deviation_cells=params.split_deviation / cell,
            length_cells=params.split_length / cell,
            max_iterations=params.max_iterations,
        )
        offset = len(result.places)
        local_owner = _own_cells(gvd)
        n = gvd.nodes.shape[0]
        z = _place_heights(local_owner, counts, heights, n)
        area = np.bincount(local_owner[local_owner >= 0], minlength=n) * cell**2
        xy = frame.centres(gvd.nodes)
        for k in range(n):
            result.places.append(
                Place(
                    terrain=terrain,
                    cell=(int(gvd.nodes[k, 0]), int(gvd.nodes[k, 1])),
                    position=np.array([xy[k, 0], xy[k, 1], z[k]]),
                    clearance=float(gvd.distance[gvd.nodes[k, 0], gvd.nodes[k, 1]] * cell),
                    area=float(area[k]),
                )
            )
        result.edges.extend(
            (offset + a, offset + b, length * cell, "gvd") for a, b, length in gvd.edges
        )
        owner = np.where(local_owner >= 0, local_owner + offset, -1)
        point_cells = frame.cells_of(layer.points[rows])
        result.point_place[rows] = owner[point_cells[:, 0], point_cells[:, 1]]
        result.gvd[terrain] = gvd
        result.cell_owner[terrain] = owner
    result.edges.extend(_traversable(result))
    return result


def place_groups(layer: PlaceLayer) -> int:
    """How many unlinked groups the places form over their ``gvd`` and ``traversable`` links."""
    n = len(layer.places)
    if n == 0:
        return 0
    pairs = np.array([(a, b) for a, b, _, _ in layer.edges], dtype=np.int64).reshape(-1, 2)
    links = sparse.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    count, _ = connected_components(links, directed=False)
    return int(count)


def warn_if_fragmented(layer: PlaceLayer, spacing: float) -> None:
    """Warn with a :class:`TerrainWarning` when the grid is too fine for the cloud's spacing
    and its places fall apart into many groups, suggesting a coarser cell."""
    groups, n = place_groups(layer), len(layer.places)
    if groups <= max(_FRAGMENTED_MIN_GROUPS, FRAGMENTED_SHARE * n):
        return
    cell = layer.frame.cell
    suggested = max(2.0 * cell, 3.0 * spacing) if math.isfinite(spacing) else 2.0 * cell
    measured = f"terrain points {spacing:.2g} m apart, " if math.isfinite(spacing) else ""
    warnings.warn(
        f"the {n} places fall into {groups} unlinked groups ({measured}{cell:g} m cells): "
        f"the terrain grid is too fine for this cloud; try a cell size of {suggested:.2g} m "
        f"(--cell-size {suggested:.2g})",
        TerrainWarning,
        stacklevel=3,
    )
