"""One query, two planners: the hierarchical planner on the 3DLSG and the volumetric baseline on
a voxel map, from the same start to the same end (000 Sec VII-C, Table 5).

Both are timed the way the paper times them: the search structures and the map are built before
the clock starts, and a query is repeated so that the reported time is a median, not one noisy
sample (a hierarchical query takes microseconds). Paths are checked segment by segment against
the true world at the robot's radius.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.geometry.raster import cells_touching_triangles
from seminspect.geometry.transforms import as_points
from seminspect.planning.hierarchical import RoutePlan
from seminspect.planning.volumetric import VolumetricPlanner
from seminspect.worlds import CollisionMode, World

#: How far (in cells) a blocked start or goal may move to a traversable cell.
END_TOLERANCE_CELLS = 2.0
#: Cell size of the fine check of paths through the whole volume [m].
FINE_CHECK_RESOLUTION = 0.05
#: Longest piece of a segment the fine check rasterises the world around at once [m].
FINE_CHECK_PIECE = 1.0


@dataclass(frozen=True)
class HierarchicalTiming:
    """Median seconds per part of a hierarchical query over its repeats.

    ``search_s`` (Target-layer search plus the Level/Pose-layer searches) is what the paper's
    Table 5 reports; ``plan_s`` adds localising the start and assembling the waypoints (the
    planner's own total), ``query_s`` is the wall time of the whole call (parsing included when
    the call parses text).
    """

    target_layer_s: float
    local_layers_s: float
    search_s: float
    plan_s: float
    query_s: float
    repeats: int


def time_hierarchical(
    run: Callable[[], RoutePlan], repeats: int
) -> tuple[RoutePlan, HierarchicalTiming]:
    """Call ``run`` (one planner query) ``repeats`` times; the plan and the median timings."""
    _check_repeats(repeats)
    plans, walls = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        plans.append(run())
        walls.append(time.perf_counter() - t0)
    target = [p.timing.target_layer_s for p in plans]
    local = [p.timing.local_layers_s for p in plans]
    timing = HierarchicalTiming(
        target_layer_s=statistics.median(target),
        local_layers_s=statistics.median(local),
        search_s=statistics.median(a + b for a, b in zip(target, local, strict=True)),
        plan_s=statistics.median(p.timing.total_s for p in plans),
        query_s=statistics.median(walls),
        repeats=repeats,
    )
    return plans[-1], timing


@dataclass(frozen=True)
class VolumetricResult:
    """The volumetric baseline's answer to one query (``error`` set when it found none)."""

    resolution: float
    time_s: float
    length: float
    expansions: int
    #: 0 when the route ends exactly at the goal; :data:`END_TOLERANCE_CELLS` cells when the
    #: goal's cell is blocked on this map and the route stops in a traversable cell near it.
    goal_radius: float
    waypoints: NDArray[np.float64]
    error: str | None = None


def time_volumetric(
    planner: VolumetricPlanner, start: ArrayLike, goal: ArrayLike, repeats: int
) -> VolumetricResult:
    """Plan ``start -> goal`` ``repeats`` times on a prepared planner; median time.

    A start or goal inside the inflated obstacles of a coarse map (the robot stood there, but
    on a coarse grid the occupied cells reach out farther than the surfaces they hold) moves to
    the nearest traversable cell within :data:`END_TOLERANCE_CELLS` cells.
    """
    _check_repeats(repeats)
    tolerance = END_TOLERANCE_CELLS * planner.grid.resolution
    try:
        radius = 0.0 if _traversable(planner, goal) else tolerance
        paths = [
            planner.plan(start, goal, goal_radius=radius, start_tolerance=tolerance)
            for _ in range(repeats)
        ]
    except PlanningError as exc:
        return VolumetricResult(
            planner.grid.resolution, math.nan, math.nan, 0, 0.0, np.empty((0, 3)), str(exc)
        )
    path = paths[-1]
    return VolumetricResult(
        resolution=planner.grid.resolution,
        time_s=statistics.median(p.planning_time for p in paths),
        length=path.length,
        expansions=path.expansions,
        goal_radius=radius,
        waypoints=path.waypoints,
    )


def _traversable(planner: VolumetricPlanner, point: ArrayLike) -> bool:
    return bool(np.isfinite(planner.grid.costs_of(planner.grid.cell_of(point, "goal"))))


def segment_validity(
    world: World, waypoints: ArrayLike, radius: float, mode: CollisionMode = "ground"
) -> NDArray[np.bool_]:
    """Whether a body of ``radius`` sweeps each segment of the path without touching the world."""
    points = as_points(waypoints, "waypoints", allow_empty=True)
    return np.array(
        [world.segment_is_free(a, b, radius, mode) for a, b in pairwise(points)],
        dtype=bool,
    )


def fine_segment_validity(
    world: World, waypoints: ArrayLike, radius: float, resolution: float = FINE_CHECK_RESOLUTION
) -> NDArray[np.bool_]:
    """Whether a sphere of ``radius`` sweeps each segment without touching the world, for paths
    through the whole volume: over objects, or close above the ground.

    The world's 3D collision grid may underestimate clearance by 0.69 m in the city, too much to
    judge a body flying 0.3 m above the ground. Here each segment, in pieces of at most
    :data:`FINE_CHECK_PIECE`, is checked against the cells of a fine grid around the piece that
    the surface touches: the surface lies within half a cell diagonal of such a cell's centre,
    so the piece is free when every centre keeps ``radius`` plus that half diagonal from it.
    (A path from free space cannot reach the inside of a solid without crossing its surface.)
    """
    points = as_points(waypoints, "waypoints", allow_empty=True)
    if not (math.isfinite(radius) and radius >= 0):
        raise InvalidInputError(f"radius must be a finite number >= 0, got {radius!r}")
    if not (math.isfinite(resolution) and resolution > 0):
        raise InvalidInputError(f"resolution must be a positive number, got {resolution!r}")
    check = _FineCheck(world.triangles, radius, resolution)
    return np.array(
        [
            all(check.piece_is_free(a + s * (b - a), a + t * (b - a)) for s, t in _pieces(a, b))
            for a, b in pairwise(points)
        ],
        dtype=bool,
    )


def _pieces(a: NDArray[np.float64], b: NDArray[np.float64]) -> list[tuple[float, float]]:
    count = max(1, math.ceil(float(np.linalg.norm(b - a)) / FINE_CHECK_PIECE))
    return list(pairwise(np.linspace(0.0, 1.0, count + 1)))


class _FineCheck:
    """Clearance of short segments from the world's surface, on a fine grid around each."""

    def __init__(self, triangles: NDArray[np.float64], radius: float, resolution: float) -> None:
        self.triangles = triangles
        self.low, self.high = triangles.min(axis=1), triangles.max(axis=1)
        self.resolution = resolution
        self.margin = radius + 2.0 * resolution
        self.needed = radius + 0.5 * math.sqrt(3.0) * resolution

    def piece_is_free(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
        lower, upper = np.minimum(a, b) - self.margin, np.maximum(a, b) + self.margin
        near = np.all((self.low <= upper) & (self.high >= lower), axis=1)
        if not near.any():
            return True
        nx, ny, nz = (int(n) for n in np.ceil((upper - lower) / self.resolution))
        shape = (nx, ny, nz)
        touched = cells_touching_triangles(self.triangles[near], lower, self.resolution, shape)
        centres = lower + (np.argwhere(touched) + 0.5) * self.resolution
        return bool(_distance_to_segment(centres, a, b).min(initial=np.inf) >= self.needed)


def _distance_to_segment(
    points: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.float64]:
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0 else np.clip((points - a) @ ab / length2, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def _check_repeats(repeats: int) -> None:
    if not (isinstance(repeats, int) and repeats >= 1):
        raise InvalidInputError(f"repeats must be a positive integer, got {repeats!r}")
