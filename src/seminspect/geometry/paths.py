"""Comparing and aligning two paths: discrete Fréchet distance, Kabsch alignment, RMSE.

Paths are ``(N, 3)`` arrays of points in order. These are the two path operators of 002
Sec III-C: the Fréchet distance ``F_D`` behind the similarity of eq (3), computed as Eiter and
Mannila's discrete coupling distance, and the rigid transform ``U*, t*`` of eq (4), found by
Kabsch's method.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import as_points


@numba.njit(cache=True)
def _frechet_kernel(p: NDArray[np.float64], q: NDArray[np.float64]) -> float:  # pragma: no cover
    n, m = p.shape[0], q.shape[0]
    row = np.empty(m)
    for i in range(n):
        diagonal = 0.0  # ca[i-1, j-1] of the row above, carried along the row
        for j in range(m):
            d = math.sqrt(((p[i] - q[j]) ** 2).sum())
            above = row[j]
            if i == 0 and j == 0:
                best = d
            elif i == 0:
                best = max(row[j - 1], d)
            elif j == 0:
                best = max(above, d)
            else:
                best = max(min(above, row[j - 1], diagonal), d)
            diagonal = above
            row[j] = best
    return row[m - 1]


def discrete_frechet(p: ArrayLike, q: ArrayLike) -> float:
    """Discrete Fréchet distance between two polylines (Eiter and Mannila 1994, 002 ref [12]).

    The smallest, over all monotone couplings of the two point sequences, of the largest
    distance between coupled points. O(N M) time, O(M) memory.
    """
    a = as_points(p, "first path")
    b = as_points(q, "second path")
    return float(_frechet_kernel(np.ascontiguousarray(a), np.ascontiguousarray(b)))


def kabsch(source: ArrayLike, target: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The rotation ``U*`` (3x3, det +1) and translation ``t*`` minimising
    ``sum ||U* s_i + t* - t_i||^2`` over paired points (Kabsch 1976, 002 eq (4)).

    With a single pair only the translation is determined; the rotation is the identity.
    """
    s = as_points(source, "source points")
    t = as_points(target, "target points")
    if s.shape != t.shape:
        raise InvalidInputError(f"Kabsch needs paired points, got {len(s)} and {len(t)}")
    s_mean, t_mean = s.mean(axis=0), t.mean(axis=0)
    if len(s) == 1:
        return np.eye(3), t_mean - s_mean
    covariance = (s - s_mean).T @ (t - t_mean)
    u, _, vt = np.linalg.svd(covariance)
    reflection = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    rotation = vt.T @ np.diag([1.0, 1.0, reflection]) @ u.T
    return rotation, t_mean - rotation @ s_mean


def apply_rigid(
    points: ArrayLike, rotation: NDArray[np.float64], translation: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``U p + t`` for each point."""
    return as_points(points, "points") @ np.asarray(rotation).T + np.asarray(translation)


def paired_rmse(p: ArrayLike, q: ArrayLike) -> float:
    """Root mean square distance between paired points of two equally long paths."""
    a = as_points(p, "first path")
    b = as_points(q, "second path")
    if a.shape != b.shape:
        raise InvalidInputError(f"paths differ in length: {len(a)} and {len(b)}")
    return float(np.sqrt(((a - b) ** 2).sum(axis=1).mean()))
