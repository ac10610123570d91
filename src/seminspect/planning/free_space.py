"""Where a robot can be on a map: the traversable cells of a cost grid, their connected
components, and rough points snapped onto them.

A user asking for a path on a map of someone else's site gives rough points: a start a hand's
width inside a wall, a goal in a pocket of free space that the map's sensor saw through a
door. :func:`snap_ends` moves each end to the nearest traversable cell (within a bound, and
says how far), preferring a component that both ends reach; when none does, the
:class:`~seminspect.core.errors.PlanningError` names both components, their sizes, and the
point of the start's component nearest the goal. Components are 26-connected in 3D and
8-connected on a planar grid, the moves the grid searches take
(:func:`~seminspect.planning.grid_astar.neighbour_steps`), so two cells of one component
always have a route between them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.geometry.transforms import as_point
from seminspect.planning.gridmap import CostGrid, format_point

#: How far an end may be moved onto free space by default [m].
DEFAULT_SNAP_M = 2.0


@dataclass(frozen=True)
class Snap:
    """A requested point and the traversable cell centre it was moved to."""

    requested: NDArray[np.float64]
    point: NDArray[np.float64]
    component: int
    moved_m: float


class FreeSpace:
    """The traversable cells of ``grid`` (finite cost) labelled by connected component.

    Components are numbered from 1, largest first (ties by lowest cell), so labels do not
    depend on scan order; 0 marks cells the robot cannot occupy. ``z_band`` keeps only cells
    whose centres lie at those heights (a robot's height limits; 3D grids only).
    """

    def __init__(self, grid: CostGrid, z_band: tuple[float, float] | None = None) -> None:
        self.grid = grid
        traversable = np.isfinite(grid.cost)
        if z_band is not None and not grid.planar:
            heights = grid.origin[2] + (np.arange(grid.shape[2]) + 0.5) * grid.resolution
            traversable &= ((heights >= z_band[0]) & (heights <= z_band[1]))[None, None, :]
        connectivity = np.ones((3, 3, 1) if grid.planar else (3, 3, 3), dtype=bool)
        raw, count = ndimage.label(traversable, structure=connectivity)
        sizes = np.bincount(raw.ravel(), minlength=count + 1)[1:]
        order = np.argsort(-sizes, kind="stable")  # label order follows the first cell
        relabel = np.zeros(count + 1, dtype=np.int32)
        relabel[order + 1] = np.arange(1, count + 1, dtype=np.int32)
        self.labels: NDArray[np.int32] = relabel[raw]
        self.sizes: NDArray[np.int64] = sizes[order].astype(np.int64)
        self.cells: NDArray[np.int64] = np.argwhere(self.labels > 0)
        self.cell_labels: NDArray[np.int32] = self.labels[tuple(self.cells.T)]

    @property
    def count(self) -> int:
        return len(self.sizes)

    def size_of(self, component: int) -> int:
        return int(self.sizes[component - 1])

    def volume_m3(self, component: int) -> float:
        return self.size_of(component) * self.grid.resolution ** (2 if self.grid.planar else 3)

    @cached_property
    def _tree(self) -> cKDTree:
        return cKDTree(self._points(self.cells))

    def _points(self, cells: NDArray[np.int64]) -> NDArray[np.float64]:
        """Cell centres in the metric the snap measures (x-y only on a planar grid)."""
        centres = self.grid.centres(cells)
        return centres[:, :2] if self.grid.planar else centres

    def _component_tree(self, component: int) -> tuple[cKDTree, NDArray[np.int64]]:
        cells = self.cells[self.cell_labels == component]
        return cKDTree(self._points(cells)), cells

    def nearest(self, point: ArrayLike, component: int | None = None) -> Snap:
        """The traversable cell centre nearest ``point`` (in ``component`` when given)."""
        if self.count == 0:
            raise PlanningError("the map has no cell the robot fits in")
        p = as_point(point, "point")
        query = p[:2] if self.grid.planar else p
        if component is None:
            distance, index = self._tree.query(query)
            cell = self.cells[int(index)]
        else:
            tree, cells = self._component_tree(component)
            distance, index = tree.query(query)
            cell = cells[int(index)]
        centre = self.grid.centres(cell[None], float(p[2]))[0]
        return Snap(p, centre, int(self.labels[tuple(cell)]), float(distance))

    def far_apart(self, component: int = 1) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Two far-apart cell centres of ``component``: the cell farthest from its centroid,
        and the cell farthest from that one (a double sweep, deterministic)."""
        if not 1 <= component <= self.count:
            raise PlanningError("the map has no cell the robot fits in")
        points = self.grid.centres(self.cells[self.cell_labels == component])
        first = points[int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))]
        second = points[int(np.argmax(np.linalg.norm(points - first, axis=1)))]
        return first, second


def snap_ends(
    space: FreeSpace, start: ArrayLike, goal: ArrayLike, max_move: float = DEFAULT_SNAP_M
) -> tuple[Snap, Snap]:
    """Start and goal moved onto traversable cells of one component, each by at most
    ``max_move`` metres: the nearest cells when they share a component, else the nearest
    cells of the component both reach with the least total move.

    Raises:
        PlanningError: an end has no traversable cell within ``max_move``, or no component
            lies within ``max_move`` of both (the message names the components and sizes).
    """
    if not (math.isfinite(max_move) and max_move >= 0):
        raise InvalidInputError(f"the snap distance must be a number >= 0, got {max_move!r}")
    first = space.nearest(start), space.nearest(goal)
    for end, snap in zip(("start", "goal"), first, strict=True):
        if snap.moved_m > max_move:
            raise PlanningError(
                f"{end} {format_point(snap.requested)} is {snap.moved_m:.2f} m from the nearest "
                f"free cell {format_point(snap.point)}, more than the {max_move:g} m it may be "
                "moved; give a point nearer free space or a larger snap distance"
            )
    if first[0].component == first[1].component:
        return first
    shared = _shared_component(space, start, goal, first, max_move)
    if shared is None:
        raise PlanningError(_cut_off_message(space, first, max_move))
    return shared


def _shared_component(
    space: FreeSpace,
    start: ArrayLike,
    goal: ArrayLike,
    first: tuple[Snap, Snap],
    max_move: float,
) -> tuple[Snap, Snap] | None:
    """The pair of snaps onto one component that moves the ends least, among the ends' own
    components and the largest."""
    best: tuple[float, Snap, Snap] | None = None
    for component in dict.fromkeys((first[0].component, first[1].component, 1)):
        s, g = space.nearest(start, component), space.nearest(goal, component)
        total = s.moved_m + g.moved_m
        if s.moved_m <= max_move and g.moved_m <= max_move and (best is None or total < best[0]):
            best = (total, s, g)
    return None if best is None else best[1:]


def _cut_off_message(space: FreeSpace, first: tuple[Snap, Snap], max_move: float) -> str:
    start, goal = first
    nearest = space.nearest(goal.requested, start.component)
    return (
        f"start {format_point(start.point)} and goal {format_point(goal.point)} lie in "
        f"different free components ({_describe(space, start.component)} and "
        f"{_describe(space, goal.component)}; the largest of {space.count} holds "
        f"{space.size_of(1)} cells) and no component lies within {max_move:g} m of both; "
        f"the start's component comes nearest the goal at {format_point(nearest.point)}, "
        f"{nearest.moved_m:.2f} m from it"
    )


def _describe(space: FreeSpace, component: int) -> str:
    return f"{space.size_of(component)} cells, {space.volume_m3(component):.1f} m³"
