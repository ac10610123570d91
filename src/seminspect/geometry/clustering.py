"""DBSCAN of 3D point clouds, compiled: the labels of scikit-learn's, without its overhead.

``dbscan_labels(points, eps, min_samples)`` returns what
``sklearn.cluster.DBSCAN(eps=eps, min_samples=min_samples).fit_predict(points)`` returns. For
clouds of 12 or more points scikit-learn answers its radius queries from a KD-tree, and this
module follows the same rules:

- the neighbours of a point are the points ``q`` (itself included) whose squared distance
  ``sum((p - q) ** 2)``, summed over x, y, z in that order, is at most ``eps * eps``;
- a core point has at least ``min_samples`` neighbours;
- clusters are numbered in the order of their lowest-indexed core point, and each is expanded
  completely before the next starts, so a border point within reach of two clusters joins the
  lower-numbered one; everything else is noise (-1).

For smaller clouds scikit-learn measures distances by matrix product (``|p|^2 - 2 p.q +
|q|^2``), whose rounding can differ from the sum above for a pair within rounding of ``eps``:
such a cloud, and only such a cloud, is handed to scikit-learn itself (importing it takes a
second and a half, so it is not done for the clouds that do not need it). Neighbours are found
on a grid of cells at least ``eps`` wide, so only the 27 cells around a point are searched.

One gap remains in theory: scikit-learn's KD-tree may admit a whole node from its bounds,
whose rounding can differ from a pair's own distance in the last bit, so a pair within an ulp
of ``eps`` could be labelled otherwise; no cloud of the tests or of the missions has shown it.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError

#: Below this many points scikit-learn measures distances by matrix product (its brute force).
MIN_GRID_POINTS = 12
#: A squared distance this close to ``eps^2``, relative to the squared norms it is computed
#: from, may round to either side of it in a matrix product (thousands of times the error
#: bound of a three-term product).
_TIE_TOLERANCE = 1e-12
#: Cells per axis at most, so that a cell's linear key fits an int64.
_MAX_CELLS_PER_AXIS = 2**20
#: Cells are this much wider than ``eps`` so that rounding in the cell index never separates
#: two neighbours by more than one cell.
_CELL_SLACK = 1.0 + 1e-6


def dbscan_labels(points: ArrayLike, eps: float, min_samples: int) -> NDArray[np.int64]:
    """DBSCAN cluster label of each point of ``points : (n, 3) float`` (-1: noise)."""
    cloud = np.ascontiguousarray(points, dtype=np.float64)
    if cloud.ndim != 2 or cloud.shape[1] != 3:
        raise InvalidInputError(f"DBSCAN needs an (n, 3) cloud, got shape {cloud.shape}")
    if not np.all(np.isfinite(cloud)):
        raise InvalidInputError("DBSCAN needs finite points")
    if not (math.isfinite(eps) and eps > 0):
        raise InvalidInputError(f"DBSCAN eps must be > 0, got {eps}")
    if not (isinstance(min_samples, int | np.integer) and min_samples >= 1):
        raise InvalidInputError(f"DBSCAN min_samples must be a positive integer, got {min_samples}")
    if not len(cloud):
        return np.empty(0, np.int64)
    if len(cloud) < MIN_GRID_POINTS and _has_pair_near_eps(cloud, eps):
        return _sklearn_labels(cloud, eps, int(min_samples))
    return _grid_labels(cloud, eps, int(min_samples))


def _has_pair_near_eps(cloud: NDArray[np.float64], eps: float) -> bool:
    """Whether two points (or a point and itself) lie so close to ``eps`` apart that a matrix
    product might put them on the other side of it than the exact sum does."""
    squared = ((cloud[:, None, :] - cloud[None, :, :]) ** 2).sum(axis=2)
    norms = (cloud**2).sum(axis=1)
    tolerance = _TIE_TOLERANCE * (norms[:, None] + norms[None, :] + eps * eps)
    return bool(np.any(np.abs(squared - eps * eps) <= tolerance))


def _sklearn_labels(cloud: NDArray[np.float64], eps: float, min_samples: int) -> NDArray[np.int64]:
    from sklearn.cluster import DBSCAN  # noqa: PLC0415 - a second to import, for tiny clouds

    labels = DBSCAN(eps=eps, min_samples=min_samples).fit_predict(cloud)
    return labels.astype(np.int64)


def _grid_labels(cloud: NDArray[np.float64], eps: float, min_samples: int) -> NDArray[np.int64]:
    """Labels from the points sorted by cell: a cell's points are contiguous, so the compiled
    distance loops read memory in order."""
    low = cloud.min(axis=0)
    span = float((cloud.max(axis=0) - low).max())
    cell = max(eps * _CELL_SLACK, span / (_MAX_CELLS_PER_AXIS - 2))
    index = np.floor((cloud - low) / cell).astype(np.int64)
    dims = index.max(axis=0) + 1
    keys = (index[:, 0] * dims[1] + index[:, 1]) * dims[2] + index[:, 2]
    order = np.argsort(keys, kind="stable")
    cell_keys, cell_start, point_cell = np.unique(
        keys[order], return_index=True, return_inverse=True
    )
    grid = (
        cloud[order],
        index[order],
        dims,
        cell_keys,
        np.append(cell_start, len(cloud)).astype(np.int64),
    )
    core = _core_points(grid, eps * eps, min_samples)
    # Seeds are taken in the caller's order: their positions in the sorted points, by index.
    seeds = np.argsort(order)
    labels = np.empty(len(cloud), np.int64)
    labels[order] = _expand(grid, point_cell.astype(np.int64), core, seeds, eps * eps)
    return labels


@numba.njit(cache=True)
def _core_points(grid, eps2, min_samples):  # pragma: no cover - compiled
    core = np.empty(len(grid[0]), np.bool_)
    for i in range(len(core)):
        core[i] = _is_core(grid, i, eps2, min_samples)
    return core


@numba.njit(cache=True)
def _cells_near(grid, i, x, y):  # pragma: no cover - compiled
    """The cells of column ``(x, y)`` within one z step of point ``i``'s cell: a range of ids.

    The three z cells of one column are consecutive keys, hence consecutive cell ids.
    """
    _, index, dims, cell_keys, _ = grid
    column = (x * dims[1] + y) * dims[2]
    z_low = max(index[i, 2] - 1, 0)
    z_high = min(index[i, 2] + 1, dims[2] - 1)
    return _first_at_least(cell_keys, column + z_low), _first_at_least(
        cell_keys, column + z_high + 1
    )


@numba.njit(cache=True)
def _first_at_least(keys, key):  # pragma: no cover - compiled
    """The first position in the sorted ``keys`` whose key is at least ``key``."""
    low, high = 0, len(keys)
    while low < high:
        middle = (low + high) // 2
        if keys[middle] < key:
            low = middle + 1
        else:
            high = middle
    return low


@numba.njit(cache=True)
def _within(points, i, j, eps2):  # pragma: no cover - compiled
    dx = points[i, 0] - points[j, 0]
    dy = points[i, 1] - points[j, 1]
    dz = points[i, 2] - points[j, 2]
    return dx * dx + dy * dy + dz * dz <= eps2


@numba.njit(cache=True)
def _is_core(grid, i, eps2, min_samples):  # pragma: no cover - compiled
    """Whether point ``i`` has ``min_samples`` neighbours: counting stops once it has."""
    points, index, dims, _, cell_start = grid
    count = 0
    for x in range(max(index[i, 0] - 1, 0), min(index[i, 0] + 2, dims[0])):
        for y in range(max(index[i, 1] - 1, 0), min(index[i, 1] + 2, dims[1])):
            first, last = _cells_near(grid, i, x, y)
            for j in range(cell_start[first], cell_start[last]):
                if _within(points, i, j, eps2):
                    count += 1
                    if count >= min_samples:
                        return True
    return False


@numba.njit(cache=True)
def _expand(grid, point_cell, core, seeds, eps2):  # pragma: no cover - compiled
    """Clusters grown from each unlabelled core point in original index order.

    A cell whose points are all labelled is skipped without measuring a distance: inside a
    dense cluster most of them soon are, so the expansion costs little more than the labels.
    """
    points, index, dims, _, cell_start = grid
    n = len(points)
    labels = np.full(n, -1, np.int64)
    unlabelled = cell_start[1:] - cell_start[:-1]
    stack = np.empty(n, np.int64)
    cluster = 0
    for seed in seeds:
        if labels[seed] != -1 or not core[seed]:
            continue
        labels[seed] = cluster
        unlabelled[point_cell[seed]] -= 1
        stack[0] = seed
        top = 1
        while top:
            top -= 1
            i = stack[top]
            if not core[i]:
                continue
            for x in range(max(index[i, 0] - 1, 0), min(index[i, 0] + 2, dims[0])):
                for y in range(max(index[i, 1] - 1, 0), min(index[i, 1] + 2, dims[1])):
                    first, last = _cells_near(grid, i, x, y)
                    for c in range(first, last):
                        if unlabelled[c] == 0:
                            continue
                        for j in range(cell_start[c], cell_start[c + 1]):
                            if labels[j] == -1 and _within(points, i, j, eps2):
                                labels[j] = cluster
                                unlabelled[c] -= 1
                                stack[top] = j
                                top += 1
        cluster += 1
    return labels
