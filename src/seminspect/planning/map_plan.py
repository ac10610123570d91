"""One volumetric path between two rough points on a map (``seminspect plan``).

The map is searched by the volumetric planner (:class:`~seminspect.planning.volumetric.
VolumetricPlanner`: optimal 26-connected A* on an inflated cost grid), after both ends are
snapped onto one free component (:func:`~seminspect.planning.free_space.snap_ends`); the route
is then shortcut on the same grid (:func:`~seminspect.planning.smoothing.refine_path`). Without
ends, the plan joins two far-apart points of the largest free component.
"""

from __future__ import annotations

import dataclasses
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.io import atomic_write_text, write_versioned_json
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.free_space import DEFAULT_SNAP_M, FreeSpace, Snap, snap_ends
from seminspect.planning.grid_astar import GridPath
from seminspect.planning.gridmap import CostModel
from seminspect.planning.smoothing import path_length, refine_path
from seminspect.planning.volumetric import VolumetricPlanner

PATH_FORMAT = "seminspect.map-path"
PATH_SUFFIXES = (".csv", ".json")


@dataclass(frozen=True)
class MapPlan:
    """A path on a map, the snapped ends it joins and what it took.

    Attributes:
        start, goal: the requested ends and where they were moved to.
        chosen: whether the ends were picked by the planner (none were given).
        path: the grid route, shortcut on the same grid (its waypoints begin and end at the
            snapped ends; ``cells`` is the raw route's).
        free_cells: traversable cells of the map; components: how many pieces they form.
        build_s: seconds spent on the cost grid and its components; search_s: on the search.
    """

    start: Snap
    goal: Snap
    chosen: bool
    path: GridPath
    resolution: float
    clearance_m: float
    free_cells: int
    components: int
    build_s: float
    search_s: float


def plan_on_map(
    voxel_map: VoxelMap,
    start: ArrayLike | None = None,
    goal: ArrayLike | None = None,
    *,
    clearance: float = 0.3,
    max_snap: float = DEFAULT_SNAP_M,
    through_unknown: bool = False,
) -> MapPlan:
    """Plan from ``start`` to ``goal`` (both or neither) keeping ``clearance`` metres from
    occupied cells; unknown cells are blocked unless ``through_unknown``.

    Raises:
        PlanningError: no free space, an end too far from it, ends cut off from each other.
    """
    if (start is None) != (goal is None):
        raise InvalidInputError("give both --start and --goal, or neither")
    began = time.perf_counter()
    model = CostModel(clearance, unknown_cost=1.0 if through_unknown else None)
    planner = VolumetricPlanner(voxel_map, model)
    space = FreeSpace(planner.grid)
    if space.count == 0:
        raise PlanningError(_no_free_space(voxel_map, clearance, through_unknown))
    chosen = start is None
    if start is None or goal is None:
        start, goal = space.far_apart()
    ends = snap_ends(space, start, goal, max_snap)
    built = time.perf_counter()
    raw = planner.plan(ends[0].point, ends[1].point)
    refined = refine_path(raw.waypoints, planner.grid).waypoints  # straight where the grid allows
    path = dataclasses.replace(raw, waypoints=refined, length=path_length(refined))
    return MapPlan(
        *ends,
        chosen=chosen,
        path=path,
        resolution=voxel_map.resolution,
        clearance_m=clearance,
        free_cells=len(space.cells),
        components=space.count,
        build_s=built - began,
        search_s=time.perf_counter() - built,
    )


def _no_free_space(voxel_map: VoxelMap, clearance: float, through_unknown: bool) -> str:
    counts = voxel_map.counts()
    if counts["free"] == 0 and not through_unknown:
        return (
            "the map holds no free cells (a point cloud knows only occupied space); "
            "allow planning through unknown space"
        )
    return f"no cell of the map keeps {clearance:g} m from every occupied cell; lower the clearance"


def write_path(path: str | os.PathLike[str], plan: MapPlan) -> Path:
    """The path's waypoints as ``.csv`` (x, y, z) or ``.json`` (with its ends and figures)."""
    target = Path(path)
    points: NDArray[np.float64] = plan.path.waypoints
    if target.suffix.lower() == ".csv":
        rows = "".join(f"{x:.4f},{y:.4f},{z:.4f}\n" for x, y, z in points)
        return atomic_write_text(target, "x,y,z\n" + rows)
    if target.suffix.lower() == ".json":
        document = {
            "start": _snap_json(plan.start),
            "goal": _snap_json(plan.goal),
            "length_m": plan.path.length,
            "cells": len(plan.path.cells),
            "resolution_m": plan.resolution,
            "clearance_m": plan.clearance_m,
            "waypoints": points.round(4).tolist(),
        }
        return write_versioned_json(target, PATH_FORMAT, 1, document, indent=2)
    raise InvalidInputError(f"{target}: a path is written as {' or '.join(PATH_SUFFIXES)}")


def _snap_json(snap: Snap) -> dict[str, object]:
    return {
        "requested": snap.requested.round(4).tolist(),
        "snapped": snap.point.round(4).tolist(),
        "moved_m": round(snap.moved_m, 4),
    }
