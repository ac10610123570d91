"""Nearest-point lookups over a fixed point set, one compiled call per query.

The hierarchical planner localises the robot with one nearest-node lookup per query. A scipy
``cKDTree`` answers it in about 9 µs, most of it the cost of calling it from Python, which is
more than the planner's searches take; this index answers in about 1 µs. Points are bucketed
by x-y in a uniform grid sized for a few points per bucket; a query scans rings of buckets
around its own until no unseen bucket can hold a closer point (3D distances, x-y buckets).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import as_point, as_points

#: Points per bucket the grid is sized for.
_PER_BUCKET = 4.0


@dataclass(frozen=True, slots=True)
class NearestIndex:
    """A static set of 3D points (see the module docstring)."""

    points: NDArray[np.float64]
    origin: NDArray[np.float64]
    cell: float
    shape: NDArray[np.int64]
    #: Bucket ``b`` holds ``order[starts[b]:starts[b + 1]]``; buckets are numbered ``i * ny + j``.
    starts: NDArray[np.int64]
    order: NDArray[np.int64]

    @classmethod
    def build(cls, points: ArrayLike) -> NearestIndex:
        pts = np.ascontiguousarray(as_points(points, "indexed points"))
        low, high = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
        area = max(float(np.prod(high - low)), 1e-6)
        cell = max(math.sqrt(area * _PER_BUCKET / len(pts)), float((high - low).max()) / 4096, 1e-3)
        shape = np.floor((high - low) / cell).astype(np.int64) + 1
        ij = np.floor((pts[:, :2] - low) / cell).astype(np.int64)
        bucket = ij[:, 0] * shape[1] + ij[:, 1]
        order = np.argsort(bucket, kind="stable")
        starts = np.zeros(int(shape.prod()) + 1, dtype=np.int64)
        np.cumsum(np.bincount(bucket, minlength=int(shape.prod())), out=starts[1:])
        return cls(pts, low, cell, shape, starts, order)

    def nearest(self, point: ArrayLike) -> tuple[int, float]:
        """Index of the stored point nearest to ``point`` (ties: lowest index) and its distance."""
        p = as_point(point, "query point")
        found, distance = _nearest(
            self.points, self.origin, self.cell, self.shape, self.starts, self.order, p
        )
        return int(found), float(distance)


@numba.njit(cache=True)
def _nearest(points, origin, cell, shape, starts, order, p):  # noqa: PLR0917
    ci = min(max(math.floor((p[0] - origin[0]) / cell), 0), shape[0] - 1)
    cj = min(max(math.floor((p[1] - origin[1]) / cell), 0), shape[1] - 1)
    best, best_d2 = -1, math.inf
    for ring in range(max(shape[0], shape[1]) + 1):
        for i in range(ci - ring, ci + ring + 1):
            if i < 0 or i >= shape[0]:
                continue
            edge = i == ci - ring or i == ci + ring
            j = cj - ring
            while j <= cj + ring:
                if 0 <= j < shape[1]:
                    b = i * shape[1] + j
                    for k in range(starts[b], starts[b + 1]):
                        n = order[k]
                        d2 = 0.0
                        for a in range(3):
                            d2 += (points[n, a] - p[a]) ** 2
                        if d2 < best_d2 or (d2 == best_d2 and n < best):
                            best, best_d2 = n, d2
                j += 1 if edge or ring == 0 else 2 * ring  # inner rows: only the two ends
        # every bucket outside this ring lies at least ``ring * cell`` away in x-y
        if best >= 0 and best_d2 <= (ring * cell) ** 2:
            break
    return best, math.sqrt(best_d2)


#: Points whose nearest neighbour is measured for the median spacing (a seeded sample).
_SPACING_SAMPLE = 20_000
#: Coincident points (repeated returns at one position) looked past for the nearest other one.
_SPACING_TWINS = 4


def median_spacing(points: ArrayLike, *, planar: bool = False, seed: int = 0) -> float:
    """Median distance from a seeded sample of points to their nearest other position (x-y
    only with ``planar``), or NaN when fewer than two distinct positions exist.

    The sample queries a tree over every point, so subsampling does not inflate the distances;
    a point's coincident twins (several returns at one position) are skipped.
    """
    cloud = np.asarray(points, dtype=np.float64)
    cloud = cloud[:, :2] if planar else cloud
    if cloud.shape[0] < 2:
        return math.nan
    sample = cloud
    if cloud.shape[0] > _SPACING_SAMPLE:
        rows = make_rng(seed, "geometry", "spacing").choice(
            cloud.shape[0], _SPACING_SAMPLE, replace=False
        )
        sample = cloud[rows]
    tree = cKDTree(cloud, balanced_tree=False, compact_nodes=False)
    distance, _ = tree.query(sample, k=min(_SPACING_TWINS + 2, cloud.shape[0]))
    apart = np.where(distance[:, 1:] > 1e-9, distance[:, 1:], np.inf).min(axis=1)
    apart = apart[np.isfinite(apart)]
    return float(np.median(apart)) if apart.size else math.nan
