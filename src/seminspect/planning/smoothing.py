"""Path refinement: drop waypoints the robot can skip by driving straight.

Grid routes zig-zag along lattice directions and graph routes visit every node on the way; both
are longer than they need to be. :func:`shortcut` walks the path and jumps from each kept waypoint
to the farthest later one it can reach in a straight line, as judged by a ``segment_is_free(a, b)``
callable, so it works for any map. By the triangle inequality it never lengthens a path, and every
segment it adds has passed the check (issue 5 section 4 uses it to close the gap between
hierarchical and volumetric path lengths).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import as_points
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.gridmap import CostGrid, CostModel

SegmentCheck = Callable[[NDArray[np.float64], NDArray[np.float64]], bool]


def path_length(waypoints: ArrayLike) -> float:
    """Length of the polyline through ``waypoints`` ``(N, 3)`` [m]."""
    pts = np.asarray(waypoints, dtype=np.float64)
    if len(pts) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def remove_collinear(waypoints: ArrayLike, tol: float = 1e-9) -> NDArray[np.float64]:
    """Drop interior waypoints lying on the straight line between their neighbours.

    Lossless: the polyline keeps its shape and length, it only loses redundant vertices.
    """
    pts = as_points(waypoints, "waypoints")
    if len(pts) < 3:
        return pts.copy()
    return pts[_collinear_kept(pts, float(tol))]


@numba.njit(cache=True)
def _collinear_kept(pts: NDArray[np.float64], tol: float) -> NDArray[np.int64]:
    """Indices kept: a point stays when it leaves the line from the last kept point to the next
    point, or turns back along it."""
    n = pts.shape[0]
    keep = np.empty(n, dtype=np.int64)
    keep[0], count = 0, 1
    for m in range(1, n - 1):
        a, b, c = pts[keep[count - 1]], pts[m], pts[m + 1]
        ab, ac = b - a, c - a
        cross = np.cross(ab, ac)
        off_line = math.sqrt(np.dot(cross, cross)) > tol * max(math.sqrt(np.dot(ac, ac)), 1.0)
        backwards = np.dot(ab, ac) < 0 or np.dot(ab, ab) > np.dot(ac, ac)
        if off_line or backwards:
            keep[count] = m
            count += 1
    keep[count] = n - 1
    return keep[: count + 1]


def shortcut(waypoints: ArrayLike, segment_is_free: SegmentCheck) -> NDArray[np.float64]:
    """Greedy shortcutting: from each kept waypoint jump to the farthest one in straight sight.

    Consecutive waypoints are always joined as they were, so the result is never longer than the
    input and contains only segments that were in the input or passed ``segment_is_free``.
    """
    pts = as_points(waypoints, "waypoints")
    kept = [0]
    n = len(pts)
    while kept[-1] < n - 1:
        i = kept[-1]
        j = n - 1
        while j > i + 1 and not segment_is_free(pts[i], pts[j]):
            j -= 1
        kept.append(j)
    return pts[kept]


@dataclass(frozen=True)
class Refinement:
    """A refined path with the figures issue 5 reports."""

    waypoints: NDArray[np.float64]
    raw_length: float
    refined_length: float
    refine_time: float


def refine_path(waypoints: ArrayLike, segment_is_free: SegmentCheck | CostGrid) -> Refinement:
    """Remove collinear vertices, then :func:`shortcut`; reports raw and refined lengths.

    Given a :class:`CostGrid`, its segment check is used and the shortcut loop runs compiled.
    """
    t0 = time.perf_counter()
    pts = as_points(waypoints, "waypoints")
    simple = remove_collinear(pts)
    if isinstance(segment_is_free, CostGrid):
        refined = simple[segment_is_free.shortcut(simple)]
    else:
        refined = shortcut(simple, segment_is_free)
    return Refinement(refined, path_length(pts), path_length(refined), time.perf_counter() - t0)


def voxel_segment_checker(
    voxel_map: VoxelMap, clearance: float, unknown_is_free: bool = False
) -> SegmentCheck:
    """A ``segment_is_free`` for a voxel map: the segment crosses only cells whose centres keep
    ``clearance`` from every occupied cell centre (and, unless ``unknown_is_free``, are known).

    The clearance field is computed once here; each check is a compiled voxel walk.
    """
    if not np.isfinite(clearance) or clearance < 0:
        raise InvalidInputError(f"clearance must be a finite number >= 0, got {clearance!r}")
    model = CostModel(clearance, risk_weight=0.0, unknown_cost=0.0 if unknown_is_free else None)
    grid = CostGrid.build(voxel_map, model)
    return grid.segment_is_free
